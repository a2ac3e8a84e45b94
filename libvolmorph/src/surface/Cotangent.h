// Cotangent weights, shared by the surface stage's maps: the rigid in-betweens' Laplacian and the
// harmonic disk map.
#pragma once

#include <volmorph/Mesh.h>

#include <cstdint>

namespace volmorph::detail {

/// Calls fn(triangle, a, b, w) once per corner of each triangle of `mesh` that has an area:
/// (a, b) is the edge opposite the corner and w = cot(the corner's angle) / 2, so that an edge's
/// weight is the sum over its triangles (the cotangent Laplacian's, negative past 90 degrees).
template <typename Fn>
void forEachCotangentWeight(const Mesh& mesh, Fn&& fn)
{
    for (uint32_t j = 0; j < mesh.triangles.size(); ++j) {
        const Vec3I& t = mesh.triangles[j];
        for (int c = 0; c < 3; ++c) {
            const uint32_t k = t[c], a = t[(c + 1) % 3], b = t[(c + 2) % 3];
            const Vec3d pk(mesh.points[k]);
            const Vec3d ea = Vec3d(mesh.points[a]) - pk, eb = Vec3d(mesh.points[b]) - pk;
            const double area2 = ea.cross(eb).length();
            if (area2 > 1e-300) fn(j, a, b, 0.5 * ea.dot(eb) / area2);
        }
    }
}

} // namespace volmorph::detail
