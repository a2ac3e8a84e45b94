// Rebuilds a blended field's narrow band as distances, and derives its fog, in one pass over the
// leaves. The blend of two distances has the right zero set but is no distance (its gradient is
// not 1); the renderer's fog ramp and the exported level set both need one.
#pragma once

#include <openvdb/openvdb.h>

#include <functional>

namespace volmorph::detail {

/// sdf and variational modes: the fog rises from 0 to 1 across this many voxels around the
/// surface.
inline constexpr float kSdfRampVoxels = 1.5f;

struct RedistanceBands {
    float voxel = 1.0f; ///< world units
    float width = 0.0f; ///< the output band's half width, world units; the grid's background
    /// The band that is kept at the leaf at `origin` (world units): only voxels within it can
    /// come within `width` of the zero set.
    std::function<float(const openvdb::Coord& origin)> keepAt;
};

/// Rewrites `values` in place: each active voxel within its leaf's kept band gets its distance to
/// the zero set to first order, |b| / |grad b| by central differences, and never more than the
/// distance to a zero crossing on one of its six edges (found by linear interpolation, as
/// OpenVDB's fast sweeping seeds its front). The band is then cut to `width` (voxels at or beyond
/// it inactive, +/- the width, tiles too). Returns the fog: fogRamp(d, rampWorld) on the band, 1
/// (active) inside, 0 outside, as fogFromLevelSet gives.
openvdb::FloatGrid::Ptr redistance(openvdb::FloatGrid& values, const RedistanceBands& bands,
                                   float rampWorld);

} // namespace volmorph::detail
