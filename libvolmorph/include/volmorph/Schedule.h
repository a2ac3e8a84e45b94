// A blend schedule: tau(t), the target's weight at morph time t, for one attribute (density,
// colour, distance); the blend stage evaluates it.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace volmorph {

/// tau(t) for one attribute. Points are (t, tau) pairs sorted by t, interpolated linearly.
struct ScheduleSpec {
    enum class Kind { Linear, Smoothstep, Sigmoid, Curve };
    Kind kind = Kind::Linear;
    double k = 8.0; ///< sigmoid steepness
    std::vector<std::pair<double, double>> points;
};

/// tau at t (clamped to [0, 1]): linear, smoothstep, a logistic sigmoid rescaled to pass through
/// (0, 0) and (1, 1), or the curve's points interpolated linearly (held beyond its ends).
double scheduleValue(const ScheduleSpec& schedule, double t);

/// d tau / dt at t: 0 outside (0, 1) and where the schedule holds; a curve's slope is its
/// segment's (the segment scheduleValue interpolates on, so the right-hand one at a point).
double scheduleSlope(const ScheduleSpec& schedule, double t);

/// "linear", "smoothstep", "sigmoid(K)" or "curve of N points", for `volmorph check`.
std::string describe(const ScheduleSpec& schedule);

} // namespace volmorph
