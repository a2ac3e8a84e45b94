// The timing stage's settings (the scene's [timing] table): where the morph happens when. A place x
// starts its morph at a delay d(x) in [0, spread] and runs it at the local time
//   tau(x, t) = clamp((t - d(x)) / (1 - spread), 0, 1),
// to which the schedules then apply: every place still goes from the source (t = 0) to the target
// (t = 1). The delay comes from a sweep (LocalTime.h) and regions that override it inside them.
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>

#include <optional>

namespace volmorph {

/// The delay grows along `direction` from 0 at the plane through `origin` to the spread at
/// `length` world units along it (clamped both sides, rounded over the first and last tenth so
/// that it is C1).
struct TimingSweep {
    Vec3d origin{0.0};
    Vec3d direction{0.0, 1.0, 0.0}; ///< unit length
    double length = 1.0;            ///< world units, > 0
    SourceLocation where;
};

struct TimingSettings {
    /// How much later the last place starts than the first, as a fraction of the morph, in
    /// [0, 1); 0 with no regions: the morph happens everywhere at once (tau = t).
    double spread = 0.0;
    std::optional<TimingSweep> sweep;
    SourceLocation where; ///< the [timing] table
};

} // namespace volmorph
