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

/// The merged triangles (`merged` positions on one input, `triangles`) with an area that face
/// against the input triangle nearest their centre (`points`, `inputTriangles`): 0 when the merged
/// mesh lies on the input as it faces (nothing folded over).
inline size_t facingAgainst(const std::vector<Vec3d>& merged, const std::vector<Vec3I>& triangles,
                            const std::vector<Vec3d>& points,
                            const std::vector<Vec3I>& inputTriangles, double diagonal)
{
    size_t against = 0;
    for (const Vec3I& t : triangles) {
        const Vec3d n = (merged[t[1]] - merged[t[0]]).cross(merged[t[2]] - merged[t[0]]);
        if (n.length() < 1e-9 * diagonal * diagonal) continue;
        const Vec3d centre = (merged[t[0]] + merged[t[1]] + merged[t[2]]) / 3.0;
        double best = std::numeric_limits<double>::infinity();
        Vec3d facing(0.0);
        for (const Vec3I& u : inputTriangles) {
            Vec3d uvw;
            const Vec3d q = openvdb::math::closestPointOnTriangleToPoint(points[u[0]], points[u[1]],
                                                                         points[u[2]], centre, uvw);
            if ((q - centre).length() < best) {
                best = (q - centre).length();
                facing = (points[u[1]] - points[u[0]]).cross(points[u[2]] - points[u[0]]);
            }
        }
        against += n.dot(facing) <= 0.0;
    }
    return against;
}

} // namespace volmorph::test
