// Feature elements of Lerios, Garfinkle and Levoy (1995), interpolated over the morph.
#pragma once

#include <volmorph/FeaturePair.h>

#include <openvdb/math/Quat.h>

#include <array>
#include <vector>

namespace volmorph {

/// A feature element in some space (world units, or index space once scaled): origin, a right-
/// handed orthonormal frame (x, y, z), scales and a type. Local coordinates u = R^T (p - c) / s.
struct Feature {
    FeatureType type = FeatureType::Point;
    Vec3d origin{0.0};
    Vec3d x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
    Vec3d scale{1.0};

    static Feature fromElement(const FeatureElement& e, FeatureType type);

    /// R^T (p - c): p in the element's frame, not divided by the scales.
    Vec3d frameCoordinates(const Vec3d& p) const
    {
        const Vec3d d = p - origin;
        return Vec3d(x.dot(d), y.dot(d), z.dot(d));
    }
    Vec3d toLocal(const Vec3d& p) const
    {
        const Vec3d q = frameCoordinates(p);
        return Vec3d(q.x() / scale.x(), q.y() / scale.y(), q.z() / scale.z());
    }
    Vec3d fromLocal(const Vec3d& u) const
    {
        return origin + x * (u.x() * scale.x()) + y * (u.y() * scale.y()) + z * (u.z() * scale.z());
    }

    /// The distance from p to the element: a point's origin; the segment of length scale.x along x;
    /// the scale.x by scale.y rectangle in the xy plane; the box (0 inside). All centred on origin.
    double distance(const Vec3d& p) const { return distanceInFrame(frameCoordinates(p)); }
    /// The same, for q = frameCoordinates(p).
    double distanceInFrame(const Vec3d& q) const;

    /// q minus its nearest point on the element, in the frame: its length is distanceInFrame(q)
    /// and, divided by that, it is the distance's gradient in the frame.
    Vec3d offsetFromElement(const Vec3d& q) const;
    /// The frame axes the element extends along, from x: 0 for a point, 1 (x) for a segment, 2
    /// for a rectangle, 3 for a box. Only their scales move the element's nearest points.
    int extendedAxes() const { return int(type); }

    /// The element's characteristic length, for Beier-Neely weights: 1 for a point, the segment's
    /// length, the rectangle's and the box's diagonal.
    double length() const;

    /// The element's edges as world-space segments, for drawing: none for a point, one for a
    /// segment, four for a rectangle, twelve for a box.
    std::vector<std::array<Vec3d, 2>> outline() const;
    /// The same element with lengths multiplied by k (world units -> index space: k = 1 / voxel).
    Feature scaled(double k) const;
};

/// The element at time t in [0, 1]: origin and scales linear, orientation by quaternion slerp
/// along the shorter arc.
Feature interpolate(const Feature& a, const Feature& b, double t);

/// The angular velocity of interpolate(a, b, t)'s frame, in radians per unit of t about world (or
/// index) axes: constant along the geodesic, so d(axis)/dt = omega x axis at every t. Between
/// frames half a turn apart the geodesic is not unique and this gives one of them.
Vec3d angularVelocity(const Feature& a, const Feature& b);

/// The unit quaternion (as openvdb::math::Quat's constructor from a Mat3 gives it) of the
/// rotation whose rows are the orthonormal frame x, y, z; also for frames a few ulps off, which
/// that constructor refuses.
openvdb::math::Quatd rotationQuaternion(const Vec3d& x, const Vec3d& y, const Vec3d& z);

} // namespace volmorph
