// Cotangent weights, shared by the surface stage's maps: the rigid in-betweens' Laplacian and the
// harmonic disk map.
#pragma once

#include <volmorph/Mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace volmorph::detail {

/// Calls fn(triangle, a, b, w) once per corner of each triangle that has an area: (a, b) is the
/// edge opposite the corner and w = cot(the corner's angle) / 2, so that an edge's weight is the
/// sum over its triangles (the cotangent Laplacian's, negative past 90 degrees). `points` are
/// Vec3f or Vec3d.
template <typename Point, typename Fn>
void forEachCotangentWeight(const std::vector<Point>& points, const std::vector<Vec3I>& triangles,
                            Fn&& fn)
{
    for (uint32_t j = 0; j < triangles.size(); ++j) {
        const Vec3I& t = triangles[j];
        for (int c = 0; c < 3; ++c) {
            const uint32_t k = t[c], a = t[(c + 1) % 3], b = t[(c + 2) % 3];
            const Vec3d pk(points[k]);
            const Vec3d ea = Vec3d(points[a]) - pk, eb = Vec3d(points[b]) - pk;
            const double area2 = ea.cross(eb).length();
            if (area2 > 1e-300) fn(j, a, b, 0.5 * ea.dot(eb) / area2);
        }
    }
}

/// The same weights from intrinsically mollified edge lengths (Sharp and Crane 2020, "A Laplacian
/// for nonmanifold triangle meshes", section 4.5): every length grows by the least epsilon that
/// makes each triangle's inequality hold by at least `delta` (world units), so that needles and
/// slivers (a merged mesh's, where an edge of one input nearly passes through a vertex of the
/// other) give bounded weights; a mesh without such triangles keeps its weights (epsilon = 0).
/// Degenerate triangles get the weights of a thin triangle instead of none.
template <typename Fn>
void forEachMollifiedCotangentWeight(const std::vector<Vec3d>& points,
                                     const std::vector<Vec3I>& triangles, double delta, Fn&& fn)
{
    auto length = [&](uint32_t u, uint32_t v) { return (points[u] - points[v]).length(); };
    double epsilon = 0.0;
    for (const Vec3I& t : triangles)
        for (int c = 0; c < 3; ++c) {
            const double opposite = length(t[(c + 1) % 3], t[(c + 2) % 3]);
            const double sides = length(t[c], t[(c + 1) % 3]) + length(t[c], t[(c + 2) % 3]);
            epsilon = std::max(epsilon, delta - (sides - opposite));
        }
    for (uint32_t j = 0; j < triangles.size(); ++j) {
        const Vec3I& t = triangles[j];
        double l[3]; // l[c]: the edge opposite corner c
        for (int c = 0; c < 3; ++c) l[c] = length(t[(c + 1) % 3], t[(c + 2) % 3]) + epsilon;
        // Heron's formula in Kahan's stable order (a >= b >= c).
        double s[3] = {l[0], l[1], l[2]};
        std::sort(s, s + 3, [](double x, double y) { return x > y; });
        const double area4 =
            std::sqrt(std::max(0.0, (s[0] + (s[1] + s[2])) * (s[2] - (s[0] - s[1])) *
                                        (s[2] + (s[0] - s[1])) * (s[0] + (s[1] - s[2]))));
        if (!(area4 > 1e-300)) continue; // all lengths 0
        for (int c = 0; c < 3; ++c) {
            const double la = l[(c + 1) % 3], lb = l[(c + 2) % 3];
            // cot = (la^2 + lb^2 - lc^2) / (4 area); w = cot / 2.
            fn(j, t[(c + 1) % 3], t[(c + 2) % 3], 0.5 * (la * la + lb * lb - l[c] * l[c]) / area4);
        }
    }
}

} // namespace volmorph::detail
