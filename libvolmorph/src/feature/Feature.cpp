#include <volmorph/Feature.h>

#include <openvdb/math/Mat3.h>
#include <openvdb/math/Quat.h>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace volmorph {

const char* toString(FeatureType type)
{
    static constexpr const char* kNames[] = {"point", "segment", "rectangle", "box"};
    static_assert(std::size(kNames) == size_t(FeatureType::Box) + 1, "a name for each type");
    return kNames[size_t(type)];
}

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
    case FeatureType::Point:
        return q.length();
    case FeatureType::Segment:
        return Vec3d(outside(q.x(), 0.5 * scale.x()), q.y(), q.z()).length();
    case FeatureType::Rectangle:
        return Vec3d(outside(q.x(), 0.5 * scale.x()), outside(q.y(), 0.5 * scale.y()), q.z())
            .length();
    case FeatureType::Box:
        return Vec3d(outside(q.x(), 0.5 * scale.x()), outside(q.y(), 0.5 * scale.y()),
                     outside(q.z(), 0.5 * scale.z()))
            .length();
    }
    return q.length();
}

Vec3d Feature::offsetFromElement(const Vec3d& q) const
{
    Vec3d v = q;
    for (int k = 0; k < extendedAxes(); ++k)
        v[k] = q[k] - std::clamp(q[k], -0.5 * scale[k], 0.5 * scale[k]);
    return v;
}

double Feature::length() const
{
    switch (type) {
    case FeatureType::Point:
        return 1.0;
    case FeatureType::Segment:
        return scale.x();
    case FeatureType::Rectangle:
        return std::hypot(scale.x(), scale.y());
    case FeatureType::Box:
        return scale.length();
    }
    return 1.0;
}

std::vector<std::array<Vec3d, 2>> Feature::outline() const
{
    // Corners in local coordinates u in {-1/2, 1/2}^3 (z = 0 for a rectangle), mapped by fromLocal.
    std::vector<std::array<Vec3d, 2>> edges;
    auto edge = [this, &edges](const Vec3d& u0, const Vec3d& u1) {
        edges.push_back({fromLocal(u0), fromLocal(u1)});
    };
    switch (type) {
    case FeatureType::Point:
        break;
    case FeatureType::Segment:
        edge(Vec3d(-0.5, 0, 0), Vec3d(0.5, 0, 0));
        break;
    case FeatureType::Rectangle:
        for (int i = 0; i < 4; ++i) {
            const double a[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
            edge(Vec3d(a[i][0], a[i][1], 0), Vec3d(a[(i + 1) % 4][0], a[(i + 1) % 4][1], 0));
        }
        break;
    case FeatureType::Box:
        // The 12 edges: along each axis, the 4 parallel edges at the other two coordinates'
        // corners.
        for (int axis = 0; axis < 3; ++axis)
            for (int corner = 0; corner < 4; ++corner) {
                Vec3d u0, u1;
                const int b = (axis + 1) % 3, c = (axis + 2) % 3;
                u0[axis] = -0.5;
                u1[axis] = 0.5;
                u0[b] = u1[b] = (corner & 1) ? 0.5 : -0.5;
                u0[c] = u1[c] = (corner & 2) ? 0.5 : -0.5;
                edge(u0, u1);
            }
        break;
    }
    return edges;
}

Feature Feature::scaled(double k) const
{
    Feature f = *this;
    f.origin *= k;
    f.scale *= k;
    return f;
}

/// Shepperd's method, in the convention of openvdb::math::Quat's constructor from a Mat3: the
/// largest of w, x, y, z first, from the trace or a diagonal entry. That constructor refuses
/// matrices whose determinant is off 1 by more than 1e-15, which an orthonormal frame computed in
/// double precision can be (a few ulps).
openvdb::math::Quatd rotationQuaternion(const Vec3d& x, const Vec3d& y, const Vec3d& z)
{
    const openvdb::math::Mat3d m(x, y, z, /*rows=*/true);
    const double trace = m(0, 0) + m(1, 1) + m(2, 2);
    double q[4]; // x, y, z, w
    if (trace > 0.0) {
        const double w = 0.5 * std::sqrt(trace + 1.0), f = 0.25 / w;
        q[0] = f * (m(1, 2) - m(2, 1));
        q[1] = f * (m(2, 0) - m(0, 2));
        q[2] = f * (m(0, 1) - m(1, 0));
        q[3] = w;
    } else {
        // The largest diagonal entry i gives the component along axis i.
        const int i = m(0, 0) > m(1, 1) && m(0, 0) > m(2, 2) ? 0 : m(1, 1) > m(2, 2) ? 1 : 2;
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        const double v = 0.5 * std::sqrt(std::max(0.0, m(i, i) - m(j, j) - m(k, k) + 1.0)),
                     f = 0.25 / v;
        q[i] = v;
        q[j] = f * (m(i, j) + m(j, i));
        q[k] = f * (m(k, i) + m(i, k));
        q[3] = f * (m(j, k) - m(k, j));
    }
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    return openvdb::math::Quatd(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
}

Vec3d angularVelocity(const Feature& a, const Feature& b)
{
    // Q = sum_k b_k a_k^T turns a's axes onto b's; the geodesic is exp(t log Q) applied to a's.
    // Its rotation vector: the axis from Q's skew part (sin), the angle with the trace (cos).
    openvdb::math::Mat3d q = openvdb::math::Mat3d::zero();
    const Vec3d* as[3] = {&a.x, &a.y, &a.z};
    const Vec3d* bs[3] = {&b.x, &b.y, &b.z};
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) q(i, j) += (*bs[k])[i] * (*as[k])[j];
    const Vec3d skew(0.5 * (q(2, 1) - q(1, 2)), 0.5 * (q(0, 2) - q(2, 0)),
                     0.5 * (q(1, 0) - q(0, 1))); // sin(theta) n
    const double sinTheta = skew.length();
    const double cosTheta = std::clamp(0.5 * (q(0, 0) + q(1, 1) + q(2, 2) - 1.0), -1.0, 1.0);
    const double theta = std::atan2(sinTheta, cosTheta);
    if (sinTheta > 1e-6) return skew * (theta / sinTheta);
    if (cosTheta > 0.0) return skew; // theta ~ sin(theta): a small or no turn
    // Near half a turn: n n^T = ((Q + Q^T) / 2 - cos I) / (1 - cos); its largest column, signed
    // as the skew part leans.
    int i = 0;
    for (int k = 1; k < 3; ++k)
        if (q(k, k) > q(i, i)) i = k;
    Vec3d n;
    for (int k = 0; k < 3; ++k)
        n[k] = (0.5 * (q(k, i) + q(i, k)) - (k == i ? cosTheta : 0.0)) / (1.0 - cosTheta);
    n.normalize();
    if (n.dot(skew) < 0.0) n = -n;
    return n * theta;
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
    const Quat qa = rotationQuaternion(a.x, a.y, a.z);
    Quat qb = rotationQuaternion(b.x, b.y, b.z);
    if (qa.dot(qb) < 0.0) qb = -qb; // q and -q are one rotation: take the shorter arc
    const Mat3 m = openvdb::math::rotation<Mat3>(openvdb::math::slerp(qa, qb, t));
    f.x = m.row(0).unit();
    f.y = m.row(1).unit();
    f.z = f.x.cross(f.y).unit();
    f.y = f.z.cross(f.x);
    return f;
}

} // namespace volmorph
