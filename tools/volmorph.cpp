// The volmorph command-line program: a thin shell of subcommands over libvolmorph.
// Exit codes are in Common.h.
#include "Common.h"

#include <volmorph/core/Version.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv)
{
    using namespace volmorph::cli;
    CLI::App app{"volmorph: feature-based volumetric morphing of meshes through OpenVDB grids"};
    app.set_version_flag("--version", std::string("volmorph ") + volmorph::versionString());
    app.require_subcommand(1);
    app.option_defaults()->always_capture_default(); // every --help shows each default
    const std::vector<Command> commands = {
        addCheckCommand(app),     addVoxelizeCommand(app), addMorphCommand(app),
        addRenderVdbCommand(app), addRenderCommand(app),   addDiffCommand(app),
        addCacheCommand(app),     addPreviewCommand(app),  addFramesCommand(app),
        addPairsCommand(app),     addEditCommand(app)};

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version arrive here too, with status 0; misuse is always status 2.
        return app.exit(e) == 0 ? 0 : kExitUsage;
    }

    try {
        for (const Command& c : commands)
            if (c.app->parsed()) return c.run();
    } catch (const volmorph::Interrupted&) {
        std::fprintf(stderr, "volmorph: interrupted; no output written for the current item\n");
        // Work left running on a stop request (an OpenVDB tool or a dense solve that takes no
        // interrupter) still uses OpenVDB's and TBB's state: exit without destroying it.
        if (volmorph::abandonedWorkRunning() > 0) {
            std::fflush(nullptr);
            std::_Exit(kExitInterrupted);
        }
        return kExitInterrupted;
    } catch (const volmorph::UserError& e) {
        for (const volmorph::Diagnostic& d : e.diagnostics())
            std::fprintf(stderr, "%s\n", d.str().c_str());
        return kExitUserError;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "volmorph: out of memory\n");
        return kExitInternal;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "volmorph: internal error: %s\n", e.what());
        return kExitInternal;
    }
    return 0;
}
