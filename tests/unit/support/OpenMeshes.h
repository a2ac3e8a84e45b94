// Meshes with holes for the voxelization tests, and their closed originals: a torus whose tube is
// cut open along an arc of its outer side, a sphere without a cap, meshes with many small holes
// and with a nested shell. All in world units.
#pragma once

#include <volmorph/Mesh.h>

#include <cmath>
#include <functional>
#include <random>
#include <unordered_set>

namespace volmorph::test {

/// A torus around z: major radius R, tube radius r, n around the axis by m around the tube. Its
/// triangles face outward.
inline Mesh torus(double R, double r, int n, int m)
{
    Mesh mesh;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < m; ++j) {
            const double phi = 2.0 * M_PI * i / n, theta = 2.0 * M_PI * j / m;
            const double rho = R + r * std::cos(theta);
            mesh.points.emplace_back(float(rho * std::cos(phi)), float(rho * std::sin(phi)),
                                     float(r * std::sin(theta)));
        }
    auto at = [n, m](int i, int j) { return uint32_t(((i + n) % n) * m + (j + m) % m); };
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < m; ++j) {
            mesh.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
            mesh.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
        }
    analyzeTopology(mesh);
    return mesh;
}

/// `mesh` without the triangles `cut` selects (by their centroid); unused points are dropped.
inline Mesh withoutTriangles(const Mesh& mesh, const std::function<bool(const Vec3d&)>& cut)
{
    Mesh out;
    std::vector<int64_t> remap(mesh.points.size(), -1);
    for (const Vec3I& t : mesh.triangles) {
        const Vec3d c =
            (Vec3d(mesh.points[t[0]]) + Vec3d(mesh.points[t[1]]) + Vec3d(mesh.points[t[2]])) / 3.0;
        if (cut(c)) continue;
        Vec3I kept;
        for (int k = 0; k < 3; ++k) {
            if (remap[t[k]] < 0) {
                remap[t[k]] = int64_t(out.points.size());
                out.points.push_back(mesh.points[t[k]]);
                if (mesh.hasColors()) out.colors.push_back(mesh.colors[t[k]]);
            }
            kept[k] = uint32_t(remap[t[k]]);
        }
        out.triangles.push_back(kept);
    }
    out.file = mesh.file;
    analyzeTopology(out);
    return out;
}

/// The fraction of `mesh`'s area whose triangles `cut` selects.
inline double areaFraction(const Mesh& mesh, const std::function<bool(const Vec3d&)>& cut)
{
    double all = 0.0, selected = 0.0;
    for (const Vec3I& t : mesh.triangles) {
        const Vec3d a(mesh.points[t[0]]), b(mesh.points[t[1]]), c(mesh.points[t[2]]);
        const double area = 0.5 * (b - a).cross(c - a).length();
        all += area;
        if (cut((a + b + c) / 3.0)) selected += area;
    }
    return selected / all;
}

/// The cut of the torus test: the outer side of the tube (within 60 degrees of the outward
/// direction around the tube) over 84 degrees around the axis, a tenth of the surface.
inline bool outerArc(const Vec3d& p, double R)
{
    const double phi = std::atan2(p.y(), p.x());
    const double rho = std::hypot(p.x(), p.y());
    const double theta = std::atan2(p.z(), rho - R);
    return std::abs(phi) < 42.0 * M_PI / 180.0 && std::abs(theta) < 60.0 * M_PI / 180.0;
}

/// `count` small holes, each the triangles whose centroid lies within `radius` of a random point
/// of the mesh (a vertex), the points at least 4 radii apart.
inline std::function<bool(const Vec3d&)> smallHoles(const Mesh& mesh, int count, double radius,
                                                    unsigned seed)
{
    std::mt19937 random(seed);
    std::vector<Vec3d> centres;
    for (int tries = 0; int(centres.size()) < count && tries < 100 * count; ++tries) {
        const Vec3d p(mesh.points[random() % mesh.points.size()]);
        bool apart = true;
        for (const Vec3d& c : centres) apart = apart && (c - p).length() > 4.0 * radius;
        if (apart) centres.push_back(p);
    }
    return [centres, radius](const Vec3d& p) {
        for (const Vec3d& c : centres)
            if ((c - p).length() < radius) return true;
        return false;
    };
}

} // namespace volmorph::test
