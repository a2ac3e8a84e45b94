// The constraints a shape places on the variational function (Interpolant.h): points spread
// evenly over its zero level set, where f = 0, and beside each a point a small offset inward along
// the normal, where f is positive, as Turk and O'Brien place their normal constraints (so f is
// positive inside and about the distance to the surface near it); and, an extension the paper
// does not make, one the same offset outward, where f is negative. Without the outward ones the
// function filled the concave gap between a dino's legs (dino-to-eight at 128 voxels across: IoU
// of the frame at t = 0 with the dino 0.962; with them at -offset 0.972; with the shape's own
// distances at both partners 0.988, BENCHMARKS.md). From the shape's signed distance grid, so that
// meshes and volumes alike give them.
#pragma once

#include "blend/variational/Interpolant.h"

#include <openvdb/Grid.h>
#include <openvdb/openvdb.h>

#include <vector>

namespace volmorph::detail::variational {

/// Each surface point is followed by its inward and its outward partner.
inline constexpr size_t kConstraintsPerPoint = 3;

/// 3 x `count` constraints (fewer when the surface has fewer voxels): `count` surface points and
/// their partners `offset` world units in and out along the normal, each with minus the shape's
/// signed distance there (about +offset in, -offset out; less where the shape is thinner than
/// twice the offset; +/-offset beyond the grid's band), all at the fourth coordinate `w` (t times
/// the time scale, world units). The surface points are the band's voxels projected onto the zero
/// set along the gradient, one per cell of a lattice sized to give about `count` cells (the one
/// nearest each cell's centre), so they cover the surface evenly; the choice is deterministic.
/// Throws std::invalid_argument when the grid holds no surface.
std::vector<Constraint> sampleConstraints(const openvdb::FloatGrid& sdf, size_t count,
                                          double offset, double w);

} // namespace volmorph::detail::variational
