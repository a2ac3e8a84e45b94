// Narrow bands of a mesh through OpenVDB's tools::meshToVolume (this is the one translation unit
// that instantiates it). The signed band of a mesh whose shells are all closed follows the
// winding-number rule without evaluating the winding number: around closed shells w is the count
// of shells that enclose p, +1 for each facing outward and -1 for each facing inward (a cavity),
// and meshToVolume gives each shell's inside exactly, with exact distances.
#pragma once

#include <volmorph/Mesh.h>

#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <vector>

namespace volmorph::detail {

/// tools::meshToVolume of `triangles` over `indexPoints` (the index space of `xform`), `halfWidth`
/// voxels each side: signed (the inside by OpenVDB's flood fill), or unsigned distances.
openvdb::FloatGrid::Ptr meshBand(const std::vector<Vec3f>& indexPoints,
                                 const std::vector<Vec3I>& triangles,
                                 const openvdb::math::Transform& xform, float halfWidth,
                                 bool unsignedDistance, openvdb::Int32Grid* index,
                                 openvdb::util::NullInterrupter& interrupter);

/// `indexPoints` are the mesh's points in the index space of `xform`. Each shell goes through
/// tools::meshToVolume (signed, `halfWidth` voxels each side); a single shell's result is returned
/// as it is. With several, a band voxel takes the smallest distance of any shell and is inside
/// when the count above is at least 1 (w > 1/2); the rest is signed by flood fill. `index`, when
/// given, receives each band voxel's closest triangle (an index into mesh.triangles).
openvdb::FloatGrid::Ptr closedShellsLevelSet(const Mesh& mesh,
                                             const std::vector<Vec3f>& indexPoints,
                                             const openvdb::math::Transform& xform, float halfWidth,
                                             openvdb::Int32Grid* index,
                                             openvdb::util::NullInterrupter& interrupter);

} // namespace volmorph::detail
