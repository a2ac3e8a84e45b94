// The approximated warp's domain test (AdaptiveWarp.h, step 4): does a cube's image, under the
// warp at t, come near an occupied block of either side? Decided before any voxel is evaluated.
#pragma once

#include "warp/Occupancy.h"

#include <volmorph/Warp.h>

#include <openvdb/Types.h>

#include <vector>

namespace volmorph::detail {

/// Trilinear sampling reads up to one voxel past the point.
inline constexpr double kSamplerReach = 1.5;

/// The box [lo, hi] widened by `margin` on every side, in whole voxels.
openvdb::CoordBBox widened(const Vec3d& lo, const Vec3d& hi, double margin);

/// Bounding box of an affine map's image of the cube [o, o + size]^3.
void affineImage(const InverseWarp::Affine& a, const Vec3d& o, double size, Vec3d& lo, Vec3d& hi);

/// Does [lo, hi] widened by `margin` meet an occupied block of `occ` (none when null)?
bool touches(const Occupancy* occ, const Vec3d& lo, const Vec3d& hi, double margin);

/// Does the cube's image under any of the affine maps (`source` and `target`, one per pair) come
/// near an occupied block? The warp is a convex combination of the pairs' maps, so a cube whose
/// images all miss both sides is empty.
bool hullMayTouch(const openvdb::CoordBBox& cube, const std::vector<InverseWarp::Affine>& source,
                  const std::vector<InverseWarp::Affine>& target, const Occupancy* sourceBlocks,
                  const Occupancy* targetBlocks);

} // namespace volmorph::detail
