// The volmorph program's main, shared by its two executables (volmorph.cpp, volmorph_image.cpp):
// the command line parsed, the chosen subcommand run, and exceptions mapped to exit codes
// (Common.h).
#include "Main.h"

#include <volmorph/core/MemoryLimit.h>
#include <volmorph/core/Version.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace volmorph::cli {

namespace {

int parseAndRun(int argc, char** argv, AddCommands addImageCommands)
{
    CLI::App app{"volmorph: feature-based volumetric morphing of meshes through OpenVDB grids"};
    app.set_version_flag("--version", std::string("volmorph ") + volmorph::versionString());
    app.require_subcommand(1);
    app.option_defaults()->always_capture_default(); // every --help shows each default
    std::vector<Command> commands;
    if (addImageCommands) addImageCommands(app, commands);
    for (const auto add : {addVoxelizeCommand, addMorphCommand, addCacheCommand, addFramesCommand,
                           addPairsCommand, addEditCommand})
        commands.push_back(add(app));

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
        return kExitInterrupted;
    } catch (const volmorph::MemoryLimitExceeded& e) {
        // The library says "raise the memory limit"; the way to do it here is the flag.
        for (const volmorph::Diagnostic& d : e.diagnostics())
            std::fprintf(stderr, "%s (--memory-limit GIB; default: half the machine's memory)\n",
                         d.str().c_str());
        return kExitUserError;
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

} // namespace

int runVolmorph(int argc, char** argv, AddCommands addImageCommands)
{
    const int status = parseAndRun(argc, argv, addImageCommands);
    // Work abandoned on a stop request (an OpenVDB tool or a dense solve that takes no interrupter)
    // may still be running, whether the command ended by Interrupted or caught the request itself
    // (the editor answers 503 and ends normally): it uses OpenVDB's and TBB's state, so exit
    // without destroying it.
    if (volmorph::abandonedWorkRunning() > 0) {
        std::fflush(nullptr);
        std::_Exit(status);
    }
    return status;
}

} // namespace volmorph::cli
