// volmorph edit SCENE [--port N]: the feature-pair editor in the browser (issue 39). Voxelizes the
// two sides at a preview resolution, then serves the page and its API on 127.0.0.1 (editor/) until
// Ctrl-C; the first line on stdout is the page's URL with its token. The scene is the only file
// it writes, and only when the page saves.
#include "Common.h"
#include "editor/EditorServer.h"
#include "editor/EditorSession.h"

#include <cstdio>
#include <memory>

namespace volmorph::cli {
namespace {

struct EditArgs {
    std::string scene, page;
    int port = 0, resolution = 128;
    bool quiet = false;
};

/// The page installed with the program: PREFIX/share/volmorph/editor beside PREFIX/bin (the build
/// tree has the same layout).
std::filesystem::path defaultPageFolder()
{
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    return self.parent_path().parent_path() / "share" / "volmorph" / "editor";
}

int runEdit(const EditArgs& args)
{
    Interrupter interrupter(false, !args.quiet);
    StopSignals signals(interrupter);
    editor::EditorSession session(args.scene, args.resolution, &interrupter);
    editor::ServerOptions options;
    options.port = args.port;
    options.assets = args.page.empty() ? defaultPageFolder() : std::filesystem::path(args.page);
    if (!args.quiet)
        std::fprintf(stderr,
                     "volmorph: editing %s (%zu pairs, previews at %d voxels across); open the URL "
                     "below in a browser, Ctrl-C to stop\n",
                     args.scene.c_str(), session.document().scene().pairs.size(), args.resolution);
    editor::serve(session, options, interrupter);
    if (session.document().text() != session.document().savedText())
        std::fprintf(stderr, "volmorph: stopped with unsaved edits; %s is as last saved\n",
                     args.scene.c_str());
    return 0;
}

} // namespace

Command addEditCommand(CLI::App& app)
{
    auto args = std::make_shared<EditArgs>();
    CLI::App* sub = app.add_subcommand(
        "edit", "Edit the scene's feature pairs in a browser, with the in-between drawn live");
    sub->add_option("SCENE", args->scene, "scene file (TOML); the only file the editor writes")
        ->required();
    sub->add_option("--port", args->port, "port on 127.0.0.1 (default: any free one)")
        ->check(CLI::Range(1, 65535));
    sub->add_option("--resolution", args->resolution,
                    "voxels across the larger side for the page's meshes and in-between")
        ->check(CLI::Range(16, 1024));
    sub->add_option("--page", args->page, "the page's folder (default: the one installed)");
    sub->add_flag("-q,--quiet", args->quiet, "print nothing but the URL");
    return {sub, [args] { return runEdit(*args); }};
}

} // namespace volmorph::cli
