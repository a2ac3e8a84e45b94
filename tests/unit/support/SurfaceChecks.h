// Measures of merged meshes for the surface stage's tests: the distance from a point to a mesh,
// and a mesh's enclosed volume and area (a merged mesh is a refinement of each input surface, so
// it has the input's volume and area).
#pragma once

#include <volmorph/core/Math.h>

#include <openvdb/math/Proximity.h>

#include <algorithm>
#include <limits>
#include <vector>

namespace volmorph::test {

/// The distance from `p` to the nearest of `triangles` (brute force).
inline double distanceTo(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                         const Vec3d& p)
{
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3I& t : triangles) {
        Vec3d uvw;
        const Vec3d q = openvdb::math::closestPointOnTriangleToPoint(points[t[0]], points[t[1]],
                                                                     points[t[2]], p, uvw);
        best = std::min(best, (q - p).length());
    }
    return best;
}

inline double volume(const std::vector<Vec3d>& p, const std::vector<Vec3I>& tris)
{
    double v = 0.0;
    for (const Vec3I& t : tris) v += p[t[0]].dot(p[t[1]].cross(p[t[2]]));
    return v / 6.0;
}

inline double area(const std::vector<Vec3d>& p, const std::vector<Vec3I>& tris)
{
    double a = 0.0;
    for (const Vec3I& t : tris) a += 0.5 * (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]).length();
    return a;
}

} // namespace volmorph::test
