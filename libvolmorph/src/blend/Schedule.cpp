#include <volmorph/Schedule.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

namespace volmorph {
namespace {

double curveValue(const std::vector<std::pair<double, double>>& points, double t)
{
    assert(points.size() >= 2);
    if (t <= points.front().first) return points.front().second;
    if (t >= points.back().first) return points.back().second;
    const auto hi =
        std::upper_bound(points.begin(), points.end(), t,
                         [](double v, const std::pair<double, double>& p) { return v < p.first; });
    const auto lo = hi - 1;
    const double span = hi->first - lo->first;
    const double a = span > 0.0 ? (t - lo->first) / span : 1.0;
    return lo->second + a * (hi->second - lo->second);
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
        auto s = [k](double x) { return 1.0 / (1.0 + std::exp(-k * (x - 0.5))); };
        const double s0 = s(0.0), s1 = s(1.0);
        return (s(t) - s0) / (s1 - s0);
    }
    case Kind::Curve:
        return curveValue(schedule.points, t);
    }
    return t;
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
