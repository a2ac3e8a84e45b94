// Dust removal for the sdf blend: a distance blend leaves small pieces where the blended field has
// an isolated minimum (or a bubble where it has a maximum inside).
#pragma once

#include <openvdb/openvdb.h>

#include <cstddef>

namespace volmorph::detail {

/// Removes dust from the blended field before its band is rebuilt: face-connected pieces of the
/// interior (values < 0) with fewer than `minVoxels` voxels, apart from the largest, become outside
/// (`outside`); bubbles, pieces of the exterior with fewer than `minVoxels` voxels enclosed by the
/// interior (no face neighbour in the background), become inside (-`outside`). Returns the count.
///
/// Active values are those within `outside` of zero; every inactive negative value (a voxel or a
/// tile) lies at least `depth` voxels inside, so its piece holds the lattice ball of that radius.
/// When `minVoxels` is at most that ball's count, only the active voxels need segmenting (the deep
/// interior would cost the most), and a small piece is large after all when a face neighbour is
/// deep inside.
size_t dropIslands(openvdb::FloatGrid& values, int minVoxels, float outside, int depth);

} // namespace volmorph::detail
