// volmorph frames SCENE [--frames SPEC] [--chunk N] [--count | --task I]: the frames of a scene cut
// into chunks, for render farms: a job array's task I renders `volmorph frames SCENE --chunk N
// --task I`. The last chunk takes the remainder.
#include "Common.h"

#include <volmorph/Frames.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

namespace volmorph::cli {
namespace {

struct FramesArgs {
    std::string scene, frames;
    int chunk = 0;
    bool count = false, outputPattern = false;
    std::optional<int> task;
};

int runFrames(const FramesArgs& args)
{
    const Scene scene = loadScene(args.scene);
    if (args.outputPattern) {
        std::printf("%s\n", std::filesystem::absolute(scene.folder / scene.frames.output)
                                .lexically_normal()
                                .c_str());
        return 0;
    }
    const std::vector<int> frames = selectFrames(scene.frames, args.frames, "--frames");
    const int size = args.chunk > 0 ? args.chunk : int(frames.size());
    const int chunks = chunkCount(frames, size);
    if (args.count) {
        std::printf("%d\n", chunks);
    } else if (args.task) {
        if (*args.task < 0 || *args.task >= chunks)
            throw UserError(SourceLocation{"--task"},
                            "task " + std::to_string(*args.task) + " does not exist: there are " +
                                std::to_string(chunks) + " chunks, 0 to " +
                                std::to_string(chunks - 1));
        std::printf("%s\n", formatFrames(chunkFrames(frames, size, *args.task)).c_str());
    } else {
        for (int i = 0; i < chunks; ++i)
            std::printf("%d %s\n", i, formatFrames(chunkFrames(frames, size, i)).c_str());
    }
    return 0;
}

} // namespace

Command addFramesCommand(CLI::App& app)
{
    auto a = std::make_shared<FramesArgs>();
    CLI::App* sub = app.add_subcommand(
        "frames", "The scene's frames cut into chunks (for job arrays on a farm)");
    sub->add_option("SCENE", a->scene, "scene file (TOML)")->required();
    sub->add_option("--frames", a->frames, "frames to cut (default: the scene's range)");
    sub->add_option("--chunk", a->chunk, "frames per chunk (default: all in one)")
        ->check(CLI::Range(1, 1000000));
    auto* count = sub->add_flag("--count", a->count, "print the number of chunks");
    sub->add_option("--task", a->task,
                    "print chunk I's frame spec (0-based, e.g. $SLURM_ARRAY_TASK_ID)")
        ->excludes(count);
    sub->add_flag("--output-pattern", a->outputPattern,
                  "print the scene's output pattern (absolute) instead");
    return {sub, [a] { return runFrames(*a); }};
}

} // namespace volmorph::cli
