// The variational function's slice at one time over a box of voxels, evaluated at every voxel: the
// reference that the frame's sparse domain (to come) is checked against, and what the topology
// tests of issue 40 read.
#pragma once

#include "blend/variational/Interpolant.h"

#include <openvdb/openvdb.h>

#include <functional>

namespace volmorph::detail::variational {

/// -f(x, y, z, w) at every voxel of `box` (index space of `transform`), so negative inside as
/// volmorph's signed distances are (not a distance: the function's own values), every voxel
/// active, background +|largest value|; a level set grid class so OpenVDB's tools read it.
openvdb::FloatGrid::Ptr sliceOverBox(const std::function<double(const Point4&)>& f, double w,
                                     const openvdb::math::Transform::Ptr& transform,
                                     const openvdb::CoordBBox& box);

/// The same slice near its zero set only, from exact values on a lattice every `stride` voxels:
/// a lattice cell is kept when its corners' values change sign, or when the smallest of them is
/// within `bandVoxels` of zero at the steepest slope between its corners (f grows about as the
/// distance near the shapes, its normal constraints' values being their offsets); kept cells and
/// their neighbours get every voxel, tricubic (Catmull-Rom) between the lattice's values: at a
/// stride of 2, within 0.01 voxel of the exact values on a sphere becoming two (4: 0.15; trilinear
/// at 2: 0.15, at 4: 0.95). The fine lattice is evaluated only in the cells of a lattice 4 strides
/// apart that the same test keeps, grown by two. `evaluations` counts the exact values taken.
openvdb::FloatGrid::Ptr sliceNearZero(const std::function<double(const Point4&)>& f, double w,
                                      const openvdb::math::Transform::Ptr& transform,
                                      const openvdb::CoordBBox& box, int stride, double bandVoxels,
                                      size_t* evaluations = nullptr);

} // namespace volmorph::detail::variational
