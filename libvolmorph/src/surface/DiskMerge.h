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
// points' positions, each taken about its loop's mean, least squares over 720 turns). Exact ties
// (two symmetric disks both put a vertex at the centre) are broken as in the star merge
// (MergeSide.h's mergeTurn).
#pragma once

#include "Correspondence.h"

namespace volmorph::detail {

/// The disk merge of `source` and `target`. With landmarks, each target point becomes a vertex of
/// the target, and the target's disk (turned as without them) is warped (DiskWarp) so that each
/// lands where the source's point is in the source's disk. Throws UserError at `where` naming the
/// mesh when it does not have exactly one boundary loop and one piece, or when its disk map folds;
/// at a landmark's pair when a point is off its surface or the landmarks fold the map.
Corresponded diskMerge(const Mesh& source, const Mesh& target,
                       const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where);

} // namespace volmorph::detail
