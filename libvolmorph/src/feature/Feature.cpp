#include <volmorph/Feature.h>

#include <openvdb/math/Mat.h>
#include <openvdb/math/Quat.h>

#include <algorithm>
#include <cmath>

namespace volmorph {

Feature Feature::fromElement(const FeatureElement& e, FeatureType type)
{
    Feature f;
    f.type = type;
    f.origin = e.origin;
    f.x = e.xAxis;
    f.y = e.yAxis;
    f.z = e.zAxis;
    f.scale = e.scale;
    return f;
}

double Feature::distanceInFrame(const Vec3d& q) const
{
    auto outside = [](double v, double half) { return std::max(std::abs(v) - half, 0.0); };
    switch (type) {
    case FeatureType::Point: return q.length();
    case FeatureType::Segment: return Vec3d(outside(q.x(), 0.5 * scale.x()), q.y(), q.z()).length();
    case FeatureType::Rectangle:
        return Vec3d(outside(q.x(), 0.5 * scale.x()), outside(q.y(), 0.5 * scale.y()), q.z()).length();
    case FeatureType::Box:
        return Vec3d(outside(q.x(), 0.5 * scale.x()), outside(q.y(), 0.5 * scale.y()),
                     outside(q.z(), 0.5 * scale.z())).length();
    }
    return q.length();
}

double Feature::length() const
{
    switch (type) {
    case FeatureType::Point: return 1.0;
    case FeatureType::Segment: return scale.x();
    case FeatureType::Rectangle: return std::hypot(scale.x(), scale.y());
    case FeatureType::Box: return scale.length();
    }
    return 1.0;
}

Feature Feature::scaled(double k) const
{
    Feature f = *this;
    f.origin *= k;
    f.scale *= k;
    return f;
}

Feature interpolate(const Feature& a, const Feature& b, double t)
{
    using Mat3 = openvdb::math::Mat3d;
    using Quat = openvdb::math::Quatd;
    Feature f;
    f.type = a.type;
    f.origin = a.origin + t * (b.origin - a.origin);
    f.scale = a.scale + t * (b.scale - a.scale);
    if (t == 0.0) {
        f.x = a.x, f.y = a.y, f.z = a.z;
        return f;
    }
    if (t == 1.0) {
        f.x = b.x, f.y = b.y, f.z = b.z;
        return f;
    }
    // Rows are the axes. Whatever convention Quat reads a Mat3 in, rotation<Mat3>() writes it back
    // in the same one, and the geodesic between two frames is the same read either way.
    const Quat qa(Mat3(a.x, a.y, a.z, /*rows=*/true));
    Quat qb(Mat3(b.x, b.y, b.z, /*rows=*/true));
    if (qa.dot(qb) < 0.0) qb = -qb; // q and -q are one rotation: take the shorter arc
    const Mat3 m = openvdb::math::rotation<Mat3>(openvdb::math::slerp(qa, qb, t));
    f.x = m.row(0).unit();
    f.y = m.row(1).unit();
    f.z = f.x.cross(f.y).unit();
    f.y = f.z.cross(f.x);
    return f;
}

} // namespace volmorph
