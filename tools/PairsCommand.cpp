// volmorph pairs suggest SCENE [-o OUT.toml]: first feature pairs from the two shapes alone
// (PairSuggest.h). Without -o the new [[pair]] tables go to stdout; with -o the scene's text with
// them appended after its own pairs (SceneDocument: every other byte kept) is written to OUT, which
// may not be the scene itself.
#include "Common.h"

#include <volmorph/PairSuggest.h>
#include <volmorph/SceneDocument.h>
#include <volmorph/core/MemoryLimit.h>

#include <cstdio>
#include <memory>

namespace volmorph::cli {
namespace {

struct PairsArgs {
    std::string scene, output;
    bool quiet = false;
    double memoryLimitGiB = 0.0;
    CacheArgs cache;
};

int runSuggest(const PairsArgs& args)
{
    // One read: the scene parsed from the very text the new file is written from.
    SceneDocument document = SceneDocument::read(args.scene);
    const Scene scene = parseScene(document.text(), args.scene);
    std::error_code ec;
    if (!args.output.empty() && std::filesystem::equivalent(args.output, args.scene, ec))
        throw UserError(SourceLocation{"-o"}, "\"" + args.output +
                                                  "\" is the scene itself; pairs suggest never "
                                                  "edits a scene in place: write a new file");
    Interrupter interrupter(false, false);
    StopSignals signals(interrupter);
    // With the pairs on stdout, nothing else goes there.
    const SceneVolumes volumes =
        loadSceneVolumes(scene, args.cache, interrupter, memoryLimitBytes(args.memoryLimitGiB),
                         args.quiet || args.output.empty());
    const PairSuggestion suggestion = suggestPairs(volumes.source, volumes.target);
    std::string printed;
    for (const FeaturePairSpec& pair : suggestion.pairs) {
        document.appendPair(pairTableLines(pair), {kSuggestedPairComment});
        printed += std::string("\n# ") + kSuggestedPairComment + "\n[[pair]]\n";
        for (const std::string& line : pairTableLines(pair)) printed += line + "\n";
    }
    if (args.output.empty()) {
        std::printf("%s", printed.c_str() + 1);
        return 0;
    }
    const auto folder = [](const std::string& p) {
        return std::filesystem::absolute(p).lexically_normal().parent_path();
    };
    if (folder(args.output) != folder(args.scene))
        std::fprintf(stderr,
                     "volmorph: warning: %s is not beside %s: the paths it names relative to the "
                     "scene's folder will be read from its own\n",
                     args.output.c_str(), args.scene.c_str());
    document.save(args.output);
    if (!args.quiet)
        std::printf("%zu pairs suggested (the box alone: IoU %.2f of the carried source with the "
                    "target), "
                    "appended after the scene's %zu -> %s\n",
                    suggestion.pairs.size(), suggestion.boxOverlap, scene.pairs.size(),
                    args.output.c_str());
    return 0;
}

} // namespace

Command addPairsCommand(CLI::App& app)
{
    auto args = std::make_shared<PairsArgs>();
    CLI::App* pairs = app.add_subcommand("pairs", "Feature pairs: suggest first ones");
    pairs->require_subcommand(1);
    CLI::App* sub = pairs->add_subcommand(
        "suggest", "Suggest feature pairs from the two shapes alone: a box pair from their "
                   "principal axes, point pairs at matched extremities");
    sub->add_option("SCENE", args->scene, "scene file (TOML)")->required();
    sub->add_option("-o,--output", args->output,
                    "write the scene with the suggested pairs appended after its own to this new "
                    "file (default: print the new [[pair]] tables on stdout)");
    sub->add_option("--memory-limit", args->memoryLimitGiB,
                    "voxelization memory limit in GiB (default: half the machine's memory)")
        ->check(CLI::PositiveNumber);
    addCacheOptions(sub, args->cache);
    sub->add_flag("-q,--quiet", args->quiet, "print nothing on success but the pairs");
    return {sub, [args] { return runSuggest(*args); }};
}

} // namespace volmorph::cli
