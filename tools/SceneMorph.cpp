#include "SceneMorph.h"

#include <volmorph/core/Version.h>

#include <string>

namespace volmorph::cli {
namespace {

bool hasSequence(const Scene& scene)
{
    return scene.source.isSequence() || scene.target.isSequence();
}

} // namespace

MorphOptions morphCommandOptions(const Scene& scene)
{
    MorphOptions options;
    options.secondsPerUnitT = scene.frames.secondsPerUnitT();
    options.velocityReachSeconds = 0.5 / scene.frames.fps;
    return options;
}

VdbWriteOptions frameVdbOptions(const Scene& scene, const std::filesystem::path& scenePath,
                                int frame, GridNames names, bool half)
{
    VdbWriteOptions write;
    write.names = names;
    write.half = half;
    write.metadata = {{"volmorph_scene", std::filesystem::absolute(scenePath).string()},
                      {"volmorph_frame", std::to_string(frame)},
                      {"volmorph_t", fmt(scene.frames.t(frame))},
                      {"volmorph_fps", fmt(scene.frames.fps)},
                      {"volmorph_version", versionString()}};
    return write;
}

SceneMorph::SceneMorph(const Scene& scene, const CacheArgs& cache, Interrupter& interrupter,
                       const MorphOptions& options, bool quiet)
    : mScene(scene), mFixed(scene), mCache(cache), mInterrupter(interrupter), mOptions(options),
      mQuiet(quiet)
{
    if (scene.blend.mode == BlendMode::Surface) {
        mSurface.emplace(scene);
        return;
    }
    if (hasSequence(scene)) {
        const Scene first = sceneAtFrame(scene, scene.frames.first);
        const auto [source, target] = sceneExtents(first, importSceneMeshes(first));
        mFixed.volume.voxelSize = sceneVoxelSize(scene.volume, source, target);
        return; // each frame loads its inputs
    }
    load(scene.frames.first);
}

void SceneMorph::load(int frame)
{
    const Scene scene = sceneAtFrame(mFixed, frame);
    const std::pair inputs{scene.source.file(), scene.target.file()};
    if (mMorpher && inputs == mLoaded) return;
    mMorpher.reset();
    SceneVolumes volumes =
        loadSceneVolumes(scene, mCache, mInterrupter, mOptions.memoryLimitBytes, mQuiet);
    MorphOptions options = mOptions;
    options.setupInterrupter = &mInterrupter;
    options.influences = std::move(volumes.influences);
    if (scene.timing.spread > 0.0)
        options.localTime =
            std::make_shared<const LocalTime>(scene.timing, std::move(volumes.timingRegions));
    mInterrupter.start("morph setup");
    mMorpher.emplace(std::move(volumes.source), std::move(volumes.target), scene.pairs, scene.warp,
                     scene.blend, options);
    mLoaded = inputs;
}

VolumeSet SceneMorph::frame(int frame, MorphStats* stats)
{
    if (hasSequence(mScene)) load(frame);
    const std::string stage = "frame " + std::to_string(frame) + ": morph";
    mInterrupter.start(stage.c_str());
    VolumeSet v = mSurface ? mSurface->voxels(mSurface->frame(frame), &mInterrupter,
                                              mOptions.memoryLimitBytes)
                           : mMorpher->frame(mScene.frames.t(frame), stats, &mInterrupter);
    if (mSurface && stats) stats->activeVoxels = v.density->activeVoxelCount();
    mInterrupter.end();
    if (mInterrupter.stopRequested()) throw Interrupted();
    return v;
}

SurfaceFrame SceneMorph::surfaceFrame(int frame)
{
    const std::string stage = "frame " + std::to_string(frame) + ": surface";
    mInterrupter.start(stage.c_str());
    SurfaceFrame f = mSurface->frame(frame);
    mInterrupter.end();
    if (mInterrupter.stopRequested()) throw Interrupted();
    return f;
}

void keepOneSide(BlendSpec& blend, bool target)
{
    ScheduleSpec held;
    held.kind = ScheduleSpec::Kind::Curve;
    const double tau = target ? 1.0 : 0.0;
    held.points = {{0.0, tau}, {1.0, tau}};
    blend.density = blend.color = blend.sdf = held;
    for (auto& entry : blend.grids) entry.second.schedule = held;
}

} // namespace volmorph::cli
