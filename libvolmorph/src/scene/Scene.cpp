// Value functions of the scene types; parsing lives in SceneParser.cpp.
#include <volmorph/Scene.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

namespace volmorph {

Mat4d ObjectTransform::matrix() const
{
    // OpenVDB matrices act on row vectors (p' = p M), so the chain below reads left to right in
    // the order the operations apply: scale, rotate X, Y, Z, translate.
    Mat4d m = Mat4d::identity();
    m.preScale(scale);  // identity scaled; order of pre/post only matters once m is non-trivial
    m.postRotate(openvdb::math::X_AXIS, rotateRadians.x());
    m.postRotate(openvdb::math::Y_AXIS, rotateRadians.y());
    m.postRotate(openvdb::math::Z_AXIS, rotateRadians.z());
    m.postTranslate(translate);
    return m;
}

Vec3d ObjectTransform::apply(const Vec3d& p) const { return matrix().transform(p); }

bool ObjectTransform::isIdentity() const
{
    return translate == Vec3d(0.0) && rotateRadians == Vec3d(0.0) && scale == Vec3d(1.0);
}

const char* toString(FeatureType type)
{
    switch (type) {
    case FeatureType::Point: return "point";
    case FeatureType::Segment: return "segment";
    case FeatureType::Rectangle: return "rectangle";
    case FeatureType::Box: return "box";
    }
    return "?";
}

double ScheduleSpec::evaluate(double t) const
{
    t = std::clamp(t, 0.0, 1.0);
    switch (kind) {
    case Kind::Linear: return t;
    case Kind::Smoothstep: return t * t * (3.0 - 2.0 * t);
    case Kind::Sigmoid: {
        // Logistic curve centred on t = 0.5, rescaled so that tau(0) = 0 and tau(1) = 1 exactly.
        auto s = [this](double x) { return 1.0 / (1.0 + std::exp(-k * (x - 0.5))); };
        const double s0 = s(0.0), s1 = s(1.0);
        return (s(t) - s0) / (s1 - s0);
    }
    case Kind::Curve: {
        assert(points.size() >= 2);
        if (t <= points.front().first) return points.front().second;
        if (t >= points.back().first) return points.back().second;
        const auto hi = std::upper_bound(points.begin(), points.end(), t,
            [](double v, const std::pair<double, double>& p) { return v < p.first; });
        const auto lo = hi - 1;
        const double span = hi->first - lo->first;
        const double a = span > 0.0 ? (t - lo->first) / span : 1.0;
        return lo->second + a * (hi->second - lo->second);
    }
    }
    return t;
}

std::string ScheduleSpec::str() const
{
    std::ostringstream s;
    switch (kind) {
    case Kind::Linear: s << "linear"; break;
    case Kind::Smoothstep: s << "smoothstep"; break;
    case Kind::Sigmoid: s << "sigmoid(" << k << ")"; break;
    case Kind::Curve:
        s << "curve of " << points.size() << " points";
        break;
    }
    return s.str();
}

double FramesSpec::t(int frame) const
{
    if (last == first) return 0.0;
    return double(frame - first) / double(last - first);
}

} // namespace volmorph
