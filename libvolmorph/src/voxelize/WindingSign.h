// The sign of an unsigned narrow band from the generalized winding number (mesh/WindingNumber.h),
// for meshes that stay open after their holes are filled: w is evaluated at the band's voxels, and
// the rest is signed by flood fill, checked against w.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/Mesh.h>

#include <openvdb/openvdb.h>

namespace volmorph::detail {

/// Replaces OpenVDB's unsigned distances by the exact distance to the closest of the closest
/// triangles of each voxel's 27-neighbourhood (`index`, meshToVolume's polygon index grid).
void refineUnsignedDistance(openvdb::FloatGrid& grid, const openvdb::Int32Grid& index,
                            const Mesh& mesh);

/// Signs the unsigned band `grid` by w > 1/2, and everything outside it; the grid becomes a level
/// set. Throws Interrupted when `interrupter` asks to stop.
void signByWindingNumber(openvdb::FloatGrid& grid, const Mesh& mesh, Interrupter* interrupter);

} // namespace volmorph::detail
