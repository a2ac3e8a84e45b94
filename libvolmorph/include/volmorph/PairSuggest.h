// First feature pairs from the two shapes alone (`volmorph pairs suggest`, issue 39), for a user
// who starts from two new meshes with no pairs at all:
// - a box pair from the principal axes of each side's density (its centroid and covariance, the box
//   spanning the shape along those axes), the target's axes matched to the source's in the order
//   and with the signs (24 right-handed frames) whose box map gives the source the largest IoU
//   with the target;
// - point pairs at matched extremities: each side's tips (the points farthest out in the box's own
//   normalized frame, at least 60 degrees apart seen from its centre), matched where a source tip
//   carried by the box map and a target tip are each other's nearest, less than 15% of the box's
//   diagonal apart (a correction near the tips, not a jump) and more than two voxels (else the box
//   alone places it). Each point carries the box's frame and scale, so its map is the box's map
//   shifted to carry tip onto tip: blended with the box's, it bends the box's map near the tip
//   only.
#pragma once

#include <volmorph/FeaturePair.h>
#include <volmorph/VolumeSet.h>

#include <vector>

namespace volmorph {

/// The comment written above each suggested [[pair]] (by `pairs suggest -o` and the editor).
inline constexpr const char* kSuggestedPairComment = "suggested by volmorph pairs suggest";

struct PairSuggestion {
    std::vector<FeaturePairSpec> pairs; ///< the box pair first, then the point pairs
    double boxOverlap = 0.0; ///< the chosen box map's IoU of the carried source with the target
                             ///< (estimated from the interior points, 0..1)
};

/// Suggests pairs from the densities of `source` and `target` (one shared transform, as
/// voxelizeScene makes them). Throws std::invalid_argument when a side is empty.
PairSuggestion suggestPairs(const VolumeSet& source, const VolumeSet& target);

} // namespace volmorph
