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

} // namespace volmorph::detail::variational
