// Morpher: (source VolumeSet, target VolumeSet, feature pairs, t) -> the in-between VolumeSet.
//
// At each t the output domain is found sparsely, each output voxel is warped back into source and
// target (the approximated warp of src/warp/AdaptiveWarp.h, or the exact one), both are resampled
// with OpenVDB's samplers, and blended: density by the density schedule, colour density-weighted
// by the colour schedule (so no colour leaks in from the side that is empty there).
//
// sdf mode blends signed distances. A narrow band clamps distances to +/- its width, and the blend
// of two clamped values, (1 - tau)(-w) + tau(+w), changes sign at tau = 1/2 everywhere at once:
// every voxel inside one object and a few voxels outside the other would flip in one frame (the
// shape snaps instead of morphing). So the Morpher first extends both distance fields over the box
// of source and target together, plus a margin, once: the band's own values near the surface,
// beyond them a field at twice the voxel size filled in by OpenVDB's fast sweeping
// (tools::maskSdf).
//
// A frame evaluates the blend only where its band can be. The blend's gradient is at most the
// warp's stretch G (distances change by at most one per unit), so a leaf or a quarter of a leaf
// whose centre value is farther from zero than G times its reach plus the band is inside or outside
// as a whole, judged from that one value. In the rest, dust is removed (blend.min_island), the
// band is rebuilt to first order (|b| / |grad b|, never beyond an edge's zero crossing), and the
// fog is derived from it. frameOverBox() evaluates every voxel instead: the tests' reference.
// With no feature pairs the warp is the identity at every t: both extended distances at a voxel
// are then the same in every frame, and are kept per leaf from the first frame that needs them,
// as are those at the leaves' centres (the frames are the same bit for bit; only the blend's
// weight changes with t). The extended fields then need only the objects' box plus 8 voxels.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/Scene.h>
#include <volmorph/VolumeSet.h>

#include <openvdb/math/Coord.h>

#include <memory>

namespace volmorph {

namespace detail {
class Occupancy;
class ExtendedDistance;
class IdentityDistances;
} // namespace detail

struct MorphOptions {
    enum class Sampling { Trilinear, Triquadratic };
    Sampling sampling = Sampling::Trilinear;
    /// A frame stops with a UserError once its output would need more than this many bytes
    /// (kMorphBytesPerLeaf per kept 8^3 leaf); 0 = half the machine's memory.
    uint64_t memoryLimitBytes = 0;
};

/// What one kept output leaf costs while a frame is made: density, colour and, in sdf mode, the
/// distance field and its fog, with the tools' temporaries (an upper estimate).
inline constexpr uint64_t kMorphBytesPerLeaf = 24 * 1024;

struct MorphStats {
    double maxWarpErrorVoxels =
        0.0; ///< largest error bound of a leaf where the warp was interpolated
    uint64_t exactEvaluations = 0; ///< exact warp evaluations (a pair of points each)
    uint64_t candidateLeaves = 0;  ///< output leaves evaluated
    uint64_t outputLeaves = 0;     ///< output leaves kept (non-empty)
    uint64_t activeVoxels = 0;     ///< of the density grid, tiles included
    uint64_t blendSamples = 0;     ///< sdf mode: points where the blend was evaluated
};

class Morpher {
public:
    /// Source and target must share one transform (voxelizeScene() makes them so).
    Morpher(VolumeSet source, VolumeSet target, std::vector<FeaturePairSpec> pairs, WarpSpec warp,
            BlendSpec blend, MorphOptions options = {});

    /// The in-between at t in [0, 1]: grids `density` and `Cd` on the shared transform.
    VolumeSet frame(double t, MorphStats* stats = nullptr,
                    Interrupter* interrupter = nullptr) const;

    /// The same, evaluated at every voxel of `box` (output index space) with no domain pruning and
    /// the given tolerance: the reference that tests compare frame() against.
    VolumeSet frameOverBox(double t, const openvdb::CoordBBox& box, double toleranceVoxels,
                           MorphStats* stats = nullptr) const;

    /// The index-space box the output at t can occupy: the active bounds of source and target,
    /// mapped by every pair's affine map (each pair alone is affine), all together, plus a margin.
    openvdb::CoordBBox candidateBounds(double t) const;

    const VolumeSet& source() const { return mSource; }
    const VolumeSet& target() const { return mTarget; }

private:
    VolumeSet run(double t, const openvdb::CoordBBox& box, bool prune, double tolerance,
                  MorphStats* stats, Interrupter* interrupter) const;
    VolumeSet runSdf(double t, const openvdb::CoordBBox& box, bool prune, double tolerance,
                     MorphStats* stats, Interrupter* interrupter) const;
    template <typename Sampler>
    VolumeSet runSdf(double t, const openvdb::CoordBBox& box, bool prune, double tolerance,
                     MorphStats* stats, Interrupter* interrupter) const;

    VolumeSet mSource, mTarget;
    /// sdf mode: the source's and target's distances extended over both objects' box (see above).
    std::shared_ptr<const detail::ExtendedDistance> mFarSource, mFarTarget;
    /// sdf mode with no pairs: both extended distances at the output voxels, kept per leaf across
    /// frames (the identity warp does not change with t). Bounded by a quarter of the memory limit.
    std::shared_ptr<detail::IdentityDistances> mIdentity;
    /// Which 8^3 blocks of source and target are occupied; they do not change with t.
    std::shared_ptr<const detail::Occupancy> mSourceBlocks, mTargetBlocks;
    std::vector<FeaturePairSpec> mPairs;
    WarpSpec mWarp;
    BlendSpec mBlend;
    MorphOptions mOptions;
};

} // namespace volmorph
