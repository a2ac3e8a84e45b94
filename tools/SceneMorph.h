// The scene's morph, ready to give frames: source and target through the voxel cache, then the
// Morpher. Shared by `morph`, `render` and `preview`.
#pragma once

#include "Common.h"

#include <volmorph/Morph.h>

#include <optional>

namespace volmorph::cli {

class SceneMorph {
public:
    /// Voxelizes (or reads from the cache) the scene's source and target, and builds the Morpher.
    SceneMorph(const Scene& scene, const CacheArgs& cache, Interrupter& interrupter,
               const MorphOptions& options, bool quiet);

    /// The in-between of frame `frame` (at its t in the scene's range). Throws Interrupted when the
    /// interrupter asked to stop during it.
    VolumeSet frame(int frame, MorphStats* stats = nullptr) const;

private:
    const Scene& mScene;
    Interrupter& mInterrupter;
    std::optional<Morpher> mMorpher;
};

} // namespace volmorph::cli
