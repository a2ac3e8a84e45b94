#include "SceneMorph.h"

#include <string>

namespace volmorph::cli {

SceneMorph::SceneMorph(const Scene& scene, const CacheArgs& cache, Interrupter& interrupter,
                       const MorphOptions& options, bool quiet)
    : mScene(scene), mInterrupter(interrupter)
{
    SceneVolumes volumes =
        loadSceneVolumes(scene, cache, interrupter, options.memoryLimitBytes, quiet);
    mMorpher.emplace(std::move(volumes.source), std::move(volumes.target), scene.pairs, scene.warp,
                     scene.blend, options);
}

VolumeSet SceneMorph::frame(int frame, MorphStats* stats) const
{
    const std::string stage = "frame " + std::to_string(frame) + ": morph";
    mInterrupter.start(stage.c_str());
    VolumeSet v = mMorpher->frame(mScene.frames.t(frame), stats, &mInterrupter);
    mInterrupter.end();
    if (mInterrupter.stopRequested()) throw Interrupted();
    return v;
}

} // namespace volmorph::cli
