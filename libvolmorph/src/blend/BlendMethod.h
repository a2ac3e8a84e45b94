// A blend method: how the two warped sides become one in-between. The Morpher finds the frame's
// domain and warp, and hands them to the method chosen by `blend.mode`; the method fills the
// output leaves and returns the grids.
//
// Adding a method: a new blend/XBlend.{h,cpp} with a class derived from BlendMethod and a
// makeXBlend(), and one line in makeBlendMethod() (BlendMethod.cpp).
#pragma once

#include "blend/OutputLeaves.h"
#include "warp/FrameWarp.h"

#include <volmorph/core/Interrupter.h>
#include <volmorph/BlendSettings.h>
#include <volmorph/LocalTime.h>
#include <volmorph/VolumeSet.h>

#include <openvdb/Types.h>

#include <cstdint>
#include <memory>

namespace volmorph::detail {

/// How the sides are read at warped points (OpenVDB's BoxSampler or QuadraticSampler).
enum class Interpolation { Trilinear, Triquadratic };

/// What a method is made from, once per morph.
struct BlendSetup {
    const VolumeSet& source; ///< both on one transform; density and Cd always, sdf for sdf mode
    const VolumeSet& target;
    const BlendSpec& spec;
    Interpolation interpolation = Interpolation::Trilinear;
    size_t pairCount = 0;               ///< no pairs: the warp is the identity at every t
    openvdb::CoordBBox candidates;      ///< the domain at t = 0 (index space), for kept values
    uint64_t memoryLimitBytes = 0;      ///< resolved (never 0)
    Interrupter* interrupter = nullptr; ///< stops the method's one-time work (null: never)
    /// Variational mode's influence shapes, on the sides' transform (null: none).
    const std::vector<TimedVolume>* influences = nullptr;
};

/// One frame's request.
struct BlendRequest {
    double t = 0.0;
    openvdb::CoordBBox box;       ///< the candidate domain (output index space)
    bool prune = true;            ///< false: every voxel of the box (the tests' reference)
    double toleranceVoxels = 0.0; ///< the approximated warp's error bound
    /// The frame's warp: at t, or at each place's local time under a timing (warp/FrameWarp.h).
    const FrameWarp* warp = nullptr;
    /// The sides' occupied blocks, to skip leaves whose image misses both (null: none skipped).
    const Occupancy* sourceBlocks = nullptr;
    const Occupancy* targetBlocks = nullptr;
    Interrupter* interrupter = nullptr;
    /// The velocity's units: world units per second of one index unit per unit t (voxel size over
    /// the seconds a unit of t lasts); 0: no velocity grid.
    double velocityScale = 0.0;
    /// The velocity also covers the voxels its motion reaches within this many seconds.
    double velocityReachSeconds = 0.0;
    /// Where the morph happens when (null: everywhere at t).
    const LocalTime* localTime = nullptr;
};

/// A method's frame: the grids (density and Cd; sdf in sdf mode), without names or transforms
/// where the caller sets them, and what it cost.
struct BlendedFrame {
    VolumeSet grids;
    size_t keptLeaves = 0;
    AdaptiveWarpStats warp;
    uint64_t blendSamples = 0; ///< points where the blend was evaluated (sdf mode)
    /// The velocity's 4^3 sub-cubes: interpolated from the leaf's lattice, and evaluated exactly.
    uint64_t velocityInterpolated = 0, velocityExact = 0;
};

class BlendMethod {
public:
    virtual ~BlendMethod() = default;
    /// The in-between for `request`; its leaves go through `leaves` (the memory guard).
    virtual BlendedFrame frame(const BlendRequest& request, OutputLeaves& leaves) const = 0;
};

/// What every method keeps: both sides (their grids shared, not copied) and the blend's settings.
class TwoSidedBlend : public BlendMethod {
protected:
    explicit TwoSidedBlend(const BlendSetup& setup)
        : mSource(setup.source), mTarget(setup.target), mSpec(setup.spec)
    {
    }

    VolumeSet mSource, mTarget;
    BlendSpec mSpec;
};

/// The method `setup.spec.mode` names.
std::unique_ptr<const BlendMethod> makeBlendMethod(const BlendSetup& setup);

/// The output's colour background at t: the sides' backgrounds mixed by the colour schedule.
Vec3f blendedColorBackground(const VolumeSet& source, const VolumeSet& target, float tauColor);

} // namespace volmorph::detail
