// The disk correspondence: two meshes with one boundary loop each (a face scan without the back of
// the head), each mapped onto the unit disk by a harmonic map (DiskMap.h), boundary onto boundary,
// and the two planar networks merged.
//
// The merge reuses the overlay on the sphere (SphereOverlay.h): the disk is lifted onto the upper
// half of the sphere by the gnomonic projection (u, v) -> (u, v, 1) / |(u, v, 1)|, which takes
// straight edges to great-circle arcs, and each side is closed by a cap: one vertex at the south
// pole joined to each boundary edge. Both boundary loops lie on the unit circle but their edges
// are different chords of it, so near the circle a point can be inside one side's disk and in
// the other's cap; there it is placed on that side's nearest boundary edge (along the ray from the
// disk's centre), so the merged mesh covers both inputs whole and its boundary runs along both
// boundaries. Regions in both caps are dropped.
//
// The target's disk is turned about its centre to best fit the source's boundary (the boundary
// points' positions, each taken about its loop's mean, least squares over 720 turns), then by a
// millionth of a radian so no vertex of one lies exactly on an edge of the other.
#pragma once

#include "Correspondence.h"

namespace volmorph::detail {

/// The disk merge of `source` and `target`. Throws UserError at `where` naming the mesh when it
/// does not have exactly one boundary loop and one piece, or when its disk map folds.
Corresponded diskMerge(const Mesh& source, const Mesh& target, const SourceLocation& where);

} // namespace volmorph::detail
