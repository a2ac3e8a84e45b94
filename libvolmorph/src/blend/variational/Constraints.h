// The constraints a shape places on the variational function (Interpolant.h): points spread
// evenly over its zero level set, where f = 0, and beside each a point a small offset inward along
// the normal, where f = +offset, as Turk and O'Brien place their normal constraints (so f is
// positive inside and about the distance to the surface near it). From the shape's signed
// distance grid, so that meshes and volumes alike give them.
#pragma once

#include "blend/variational/Interpolant.h"

#include <openvdb/Grid.h>
#include <openvdb/openvdb.h>

#include <vector>

namespace volmorph::detail::variational {

/// 2 x `count` constraints (fewer when the surface has fewer voxels): `count` surface points and
/// their inward partners `offset` world units in, all at the fourth coordinate `w` (t times the
/// time scale, world units). The surface points are the band's voxels projected onto the zero
/// set along the gradient, one per cell of a lattice sized to give about `count` cells (the one
/// nearest each cell's centre), so they cover the surface evenly; the choice is deterministic.
/// Throws std::invalid_argument when the grid holds no surface.
std::vector<Constraint> sampleConstraints(const openvdb::FloatGrid& sdf, size_t count,
                                          double offset, double w);

} // namespace volmorph::detail::variational
