// Feature pairs as a user writes them (Lerios et al. 1995): the feature stage's input, and what the
// scene file's [[pair]] tables and the editor build.
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>

namespace volmorph {

enum class FeatureType { Point, Segment, Rectangle, Box };
const char* toString(FeatureType type);

/// One feature element: an origin, an orthonormal frame and scales. The type only chooses the
/// distance function; a segment is scale.x long along xAxis, a rectangle scale.x by scale.y in the
/// xAxis-yAxis plane, a box scale.x by scale.y by scale.z; all centred on origin.
struct FeatureElement {
    Vec3d origin{0.0, 0.0, 0.0}; ///< world units
    Vec3d xAxis{1.0, 0.0, 0.0};  ///< unit length; the frame is orthonormal and right-handed
    Vec3d yAxis{0.0, 1.0, 0.0};
    Vec3d zAxis{0.0, 0.0, 1.0};
    Vec3d scale{1.0, 1.0, 1.0}; ///< world units, every component > 0
};

struct FeaturePairSpec {
    FeatureType type = FeatureType::Point;
    FeatureElement source;
    FeatureElement target;
    SourceLocation where; ///< where the pair was written (a scene's [[pair]] header), if anywhere
};

} // namespace volmorph
