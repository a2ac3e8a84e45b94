// Morpher: (source VolumeSet, target VolumeSet, feature pairs, t) -> the in-between VolumeSet.
//
// At each t the output domain is found sparsely, each output voxel is warped back into source and
// target (the approximated warp of src/warp/AdaptiveWarp.h, or the exact one), both are resampled
// with OpenVDB's samplers, and blended by the method `blend.mode` names (src/blend/): density mode
// mixes the densities by the density schedule; sdf mode blends signed distances extended beyond
// their bands, so the surface morphs instead of snapping (src/blend/SdfBlend.h). Colour is mixed
// by the colour schedule, weighted by each side's density (no colour leaks in from the side that
// is empty there). frameOverBox() evaluates every voxel instead: the tests' reference.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/BlendSettings.h>
#include <volmorph/LocalTime.h>
#include <volmorph/FeaturePair.h>
#include <volmorph/WarpSettings.h>
#include <volmorph/VolumeSet.h>

#include <openvdb/math/Coord.h>

#include <memory>

namespace volmorph {

namespace detail {
class Occupancy;
class BlendMethod;
struct TauTable;
} // namespace detail

struct MorphOptions {
    enum class Sampling { Trilinear, Triquadratic };
    Sampling sampling = Sampling::Trilinear;
    /// A frame stops with a UserError once the process would hold more than this many bytes: what
    /// it holds when the frame starts (the inputs, the setup, residentBytes()) plus its output,
    /// kMorphBytesPerLeaf (kDensityBytesPerLeaf in density mode) and the carried grids' bytes per
    /// kept 8^3 leaf; 0 = half the machine's memory.
    uint64_t memoryLimitBytes = 0;
    /// The `vel` grid's time unit: the seconds one unit of t lasts ((last - first) / fps for a
    /// frame range). 0: no velocity grid.
    double secondsPerUnitT = 0.0;
    /// The `vel` grid also covers every voxel its motion reaches within this many seconds of the
    /// frame (the shutter's reach), with the warp's own velocity there: Eulerian motion blur reads
    /// the velocity where the density is about to arrive.
    double velocityReachSeconds = 0.0;
    /// Stops the one-time setup of the blend (sdf mode's extended distances) when it asks to,
    /// with volmorph::Interrupted; null: never stops. Frames take their own.
    Interrupter* setupInterrupter = nullptr;
    /// Variational mode's influence shapes (SceneVolumes::influences), on the sides' transform.
    std::vector<TimedVolume> influences;
    /// Where the morph happens when ([timing]); null or inactive: everywhere at once. Density and
    /// sdf modes honour it, the warp too (each place at its local time: src/warp/TimedWarp.h);
    /// the variational method does not (the scene refuses it).
    std::shared_ptr<const LocalTime> localTime;
};

/// What one kept output leaf costs while an sdf-mode frame is made: density, colour, the distance
/// field and its fog, with the tools' temporaries (an upper estimate).
inline constexpr uint64_t kMorphBytesPerLeaf = 24 * 1024;
/// The same in density mode: a density and a colour leaf with their masks and bookkeeping (8.6 KiB
/// a kept block measured at 1000 voxels across, BENCHMARKS.md), with a margin.
inline constexpr uint64_t kDensityBytesPerLeaf = 12 * 1024;
/// What the velocity adds per kept leaf: its values and mask, and both sides' velocities while
/// the leaf is filled; in sdf mode also each side's distance and the normal correction (an upper
/// estimate for both modes).
inline constexpr uint64_t kVelocityBytesPerLeaf = 17 * 1024;

struct MorphStats {
    double maxWarpErrorVoxels =
        0.0; ///< largest error bound of a leaf where the warp was interpolated
    uint64_t exactEvaluations = 0; ///< exact warp evaluations (a pair of points each)
    uint64_t candidateLeaves = 0;  ///< output leaves evaluated
    uint64_t outputLeaves = 0;     ///< output leaves kept (non-empty)
    uint64_t activeVoxels = 0;     ///< of the density grid, tiles included
    uint64_t blendSamples = 0;     ///< sdf mode: points where the blend was evaluated
    /// Velocity: 4^3 sub-cubes interpolated from their leaf's lattice, and evaluated exactly.
    uint64_t velocityInterpolated = 0, velocityExact = 0;
};

class Morpher {
public:
    /// Source and target must share one transform (voxelizeScene() makes them so).
    Morpher(VolumeSet source, VolumeSet target, std::vector<FeaturePairSpec> pairs, WarpSpec warp,
            BlendSpec blend, MorphOptions options = {});

    /// The same morph with other pairs, sharing this one's blend setup (sdf mode's extended
    /// distances, which depend on the two sides alone) when both this and `pairs` have pairs, and
    /// always in variational mode (which uses no pairs); built anew when either has none (the
    /// identity warp sets up differently). What an editor does
    /// after each change to the pairs: frames are bit for bit those of a Morpher built with them.
    Morpher withPairs(std::vector<FeaturePairSpec> pairs) const;

    /// The same morph under another timing (null: everywhere at once), sharing this one's blend
    /// setup (which does not depend on it): what an editor does after the sweep is dragged.
    Morpher withTiming(std::shared_ptr<const LocalTime> localTime) const;

    /// The in-between at t in [0, 1]: grids `density` and `Cd` on the shared transform.
    VolumeSet frame(double t, MorphStats* stats = nullptr,
                    Interrupter* interrupter = nullptr) const;

    /// The same, evaluated at every voxel of `box` (output index space) with no domain pruning and
    /// the given tolerance: the reference that tests compare frame() against.
    VolumeSet frameOverBox(double t, const openvdb::CoordBBox& box, double toleranceVoxels,
                           MorphStats* stats = nullptr) const;

    /// The index-space box the output at t can occupy: the active bounds of source and target,
    /// mapped by every pair's affine map (each pair alone is affine), all together, plus a margin;
    /// under a timing, the union of those at every local time the warp's table holds.
    openvdb::CoordBBox candidateBounds(double t) const;

    const VolumeSet& source() const { return mSource; }
    const VolumeSet& target() const { return mTarget; }

private:
    VolumeSet run(double t, const openvdb::CoordBBox& box, bool prune, double tolerance,
                  MorphStats* stats, Interrupter* interrupter) const;
    /// candidateBounds() with every place at t.
    openvdb::CoordBBox boundsAt(double t) const;
    /// True under an active timing.
    bool timed() const;
    /// The warp's table over local time, under a timing with pairs (else none).
    void tabulate();

    VolumeSet mSource, mTarget;
    /// The blend method (with what it keeps across frames: sdf mode's extended distances).
    std::shared_ptr<const detail::BlendMethod> mMethod;
    /// Which 8^3 blocks of source and target are occupied; they do not change with t.
    std::shared_ptr<const detail::Occupancy> mSourceBlocks, mTargetBlocks;
    std::vector<FeaturePairSpec> mPairs;
    /// Under a timing with pairs: the warp's levels over local time (warp/TimedWarp.h).
    std::shared_ptr<const detail::TauTable> mTauTable;
    WarpSpec mWarp;
    BlendSpec mBlend;
    MorphOptions mOptions;
};

} // namespace volmorph
