// The scene's morph, ready to give frames: source and target through the voxel cache, then the
// Morpher. Shared by `morph`, `render` and `preview`. A side that is a volume sequence changes with
// the frame: its file for each frame is read (through the cache, keyed on that file) and the
// Morpher rebuilt when a frame's inputs differ from the last frame's. In surface mode the frames
// are the surface stage's meshes voxelized at the scene's voxel size (SceneSurface.h).
#pragma once

#include "Common.h"

#include <volmorph/Morph.h>
#include <volmorph/SceneSurface.h>

#include <filesystem>
#include <optional>
#include <utility>

namespace volmorph::cli {

/// Holds every schedule of `blend` (density, colour, sdf and the carried grids') at 0 (the source)
/// or 1 (`target`): the morph then shows that side alone, warped at each frame's t.
void keepOneSide(BlendSpec& blend, bool target);

/// `volmorph morph`'s options: the vel grid (world units per second) over half a frame either
/// way, Blender's and Houdini's default shutters, centred.
MorphOptions morphCommandOptions(const Scene& scene);

/// How `volmorph morph` writes frame `frame` (at `t`) of the scene file `scenePath`: the grid
/// names of `names`, its metadata (volmorph_scene, _frame, _t, _fps, _version).
VdbWriteOptions frameVdbOptions(const Scene& scene, const std::filesystem::path& scenePath,
                                int frame, GridNames names, bool half);

class SceneMorph {
public:
    /// Voxelizes (or reads from the cache) the scene's source and target, and builds the Morpher.
    /// With a sequence, the voxel size is fixed from the scene's first frame (one grid for all).
    SceneMorph(const Scene& scene, const CacheArgs& cache, Interrupter& interrupter,
               const MorphOptions& options, bool quiet);

    /// The in-between of frame `frame` (at its t in the scene's range). Throws Interrupted when the
    /// interrupter asked to stop during it.
    VolumeSet frame(int frame, MorphStats* stats = nullptr);

    /// Surface mode (blend.mode = "surface"): its frames are meshes (surfaceFrame), and frame()
    /// gives them voxelized.
    bool surfaceMode() const { return mSurface.has_value(); }
    /// Surface mode: the in-between mesh of frame `frame`, velocities in world units per second.
    SurfaceFrame surfaceFrame(int frame);

private:
    void load(int frame);

    const Scene& mScene;
    Scene mFixed; ///< the scene with a sequence's voxel size fixed
    CacheArgs mCache;
    Interrupter& mInterrupter;
    MorphOptions mOptions;
    bool mQuiet;
    std::pair<std::filesystem::path, std::filesystem::path> mLoaded; ///< the Morpher's inputs
    std::optional<Morpher> mMorpher;
    std::optional<SceneSurface> mSurface; ///< surface mode
};

} // namespace volmorph::cli
