#include <volmorph/Schedule.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

namespace volmorph {
namespace {

using Points = std::vector<std::pair<double, double>>;

/// The segment of the curve that holds t (strictly between the first and last points).
Points::const_iterator segmentEnd(const Points& points, double t)
{
    return std::upper_bound(
        points.begin(), points.end(), t,
        [](double v, const std::pair<double, double>& p) { return v < p.first; });
}

double curveValue(const Points& points, double t)
{
    assert(points.size() >= 2);
    if (t <= points.front().first) return points.front().second;
    if (t >= points.back().first) return points.back().second;
    const auto hi = segmentEnd(points, t);
    const auto lo = hi - 1;
    const double span = hi->first - lo->first;
    const double a = span > 0.0 ? (t - lo->first) / span : 1.0;
    return lo->second + a * (hi->second - lo->second);
}

double curveSlope(const Points& points, double t)
{
    if (t <= points.front().first || t >= points.back().first) return 0.0;
    const auto hi = segmentEnd(points, t);
    const auto lo = hi - 1;
    const double span = hi->first - lo->first;
    return span > 0.0 ? (hi->second - lo->second) / span : 0.0;
}

/// The logistic curve centred on t = 0.5 with steepness k.
double logistic(double k, double x)
{
    return 1.0 / (1.0 + std::exp(-k * (x - 0.5)));
}

} // namespace

double scheduleValue(const ScheduleSpec& schedule, double t)
{
    using Kind = ScheduleSpec::Kind;
    t = std::clamp(t, 0.0, 1.0);
    switch (schedule.kind) {
    case Kind::Linear:
        return t;
    case Kind::Smoothstep:
        return t * t * (3.0 - 2.0 * t);
    case Kind::Sigmoid: {
        // Logistic curve centred on t = 0.5, rescaled so that tau(0) = 0 and tau(1) = 1 exactly.
        const double k = schedule.k;
        const double s0 = logistic(k, 0.0), s1 = logistic(k, 1.0);
        return (logistic(k, t) - s0) / (s1 - s0);
    }
    case Kind::Curve:
        return curveValue(schedule.points, t);
    }
    return t;
}

double scheduleSlope(const ScheduleSpec& schedule, double t)
{
    using Kind = ScheduleSpec::Kind;
    if (t < 0.0 || t > 1.0) return 0.0;
    switch (schedule.kind) {
    case Kind::Linear:
        return 1.0;
    case Kind::Smoothstep:
        return 6.0 * t * (1.0 - t);
    case Kind::Sigmoid: {
        const double k = schedule.k, s = logistic(k, t);
        return k * s * (1.0 - s) / (logistic(k, 1.0) - logistic(k, 0.0));
    }
    case Kind::Curve:
        return curveSlope(schedule.points, t);
    }
    return 1.0;
}

std::string describe(const ScheduleSpec& schedule)
{
    using Kind = ScheduleSpec::Kind;
    std::ostringstream s;
    switch (schedule.kind) {
    case Kind::Linear:
        s << "linear";
        break;
    case Kind::Smoothstep:
        s << "smoothstep";
        break;
    case Kind::Sigmoid:
        s << "sigmoid(" << schedule.k << ")";
        break;
    case Kind::Curve:
        s << "curve of " << schedule.points.size() << " points";
        break;
    }
    return s.str();
}

} // namespace volmorph
