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
    m.preScale(scale); // identity scaled; order of pre/post only matters once m is non-trivial
    m.postRotate(openvdb::math::X_AXIS, rotateRadians.x());
    m.postRotate(openvdb::math::Y_AXIS, rotateRadians.y());
    m.postRotate(openvdb::math::Z_AXIS, rotateRadians.z());
    m.postTranslate(translate);
    return m;
}

Vec3d ObjectTransform::apply(const Vec3d& p) const
{
    return matrix().transform(p);
}

bool ObjectTransform::isIdentity() const
{
    return translate == Vec3d(0.0) && rotateRadians == Vec3d(0.0) && scale == Vec3d(1.0);
}

const char* toString(FeatureType type)
{
    switch (type) {
    case FeatureType::Point:
        return "point";
    case FeatureType::Segment:
        return "segment";
    case FeatureType::Rectangle:
        return "rectangle";
    case FeatureType::Box:
        return "box";
    }
    return "?";
}

double ScheduleSpec::evaluate(double t) const
{
    t = std::clamp(t, 0.0, 1.0);
    switch (kind) {
    case Kind::Linear:
        return t;
    case Kind::Smoothstep:
        return t * t * (3.0 - 2.0 * t);
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
        const auto hi = std::upper_bound(
            points.begin(), points.end(), t,
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
    case Kind::Linear:
        s << "linear";
        break;
    case Kind::Smoothstep:
        s << "smoothstep";
        break;
    case Kind::Sigmoid:
        s << "sigmoid(" << k << ")";
        break;
    case Kind::Curve:
        s << "curve of " << points.size() << " points";
        break;
    }
    return s.str();
}

namespace {

/// The two keys around `frame` and the weight of the second; the same key twice outside them.
template <typename Key>
void around(const std::vector<Key>& keys, int frame, const Key*& a, const Key*& b, double& u)
{
    a = b = &keys.front();
    u = 0.0;
    if (frame <= keys.front().frame) return;
    a = b = &keys.back();
    if (frame >= keys.back().frame) return;
    for (size_t i = 1; i < keys.size(); ++i) {
        if (frame <= keys[i].frame) {
            a = &keys[i - 1];
            b = &keys[i];
            u = double(frame - a->frame) / double(b->frame - a->frame);
            return;
        }
    }
}

Vec3d lerp(const Vec3d& a, const Vec3d& b, double u)
{
    return a + (b - a) * u;
}

/// Linear interpolation of two directions, renormalized (keys may not be opposite: the parser
/// refuses that).
Vec3d lerpDirection(const Vec3d& a, const Vec3d& b, double u)
{
    const Vec3d d = lerp(a.unit(), b.unit(), u);
    return d.length() > 1e-12 ? d.unit() : a.unit();
}

} // namespace

CameraSpec CameraSpec::at(int frame) const
{
    CameraSpec c = *this;
    if (keys.empty()) return c;
    const CameraKey *a, *b;
    double u;
    around(keys, frame, a, b, u);
    c.eye = lerp(a->eye, b->eye, u);
    c.lookat = lerp(a->lookat, b->lookat, u);
    c.up = lerpDirection(a->up, b->up, u);
    c.fovDegrees = a->fovDegrees + (b->fovDegrees - a->fovDegrees) * u;
    c.orthoWidth = a->orthoWidth + (b->orthoWidth - a->orthoWidth) * u;
    c.keys.clear();
    return c;
}

LightSpec LightSpec::at(int frame) const
{
    LightSpec l = *this;
    if (keys.empty()) return l;
    const LightKey *a, *b;
    double u;
    around(keys, frame, a, b, u);
    l.direction = lerpDirection(a->direction, b->direction, u);
    l.position = lerp(a->position, b->position, u);
    l.color = lerp(a->color, b->color, u);
    l.intensity = a->intensity + (b->intensity - a->intensity) * u;
    l.keys.clear();
    return l;
}

double FramesSpec::t(int frame) const
{
    if (last == first) return 0.0;
    return double(frame - first) / double(last - first);
}

} // namespace volmorph
