// Meshes for the surface stage's tests, in world units. Closed, facing outward: a tube along x with
// capped ends (and the same bent in a plane), a latitude-longitude sphere whose radius may vary
// with direction (a star-shaped blob), a cube. With one boundary loop: a dome and a bumpy sheet.
#pragma once

#include <volmorph/Mesh.h>

#include <cmath>
#include <functional>

namespace volmorph::test {

/// A closed tube along x from 0 to `length`, radius `radius`: `rings` rings of `around` vertices
/// and a centre vertex closing each end.
inline Mesh tube(int rings, int around, double length, double radius)
{
    Mesh m;
    for (int i = 0; i < rings; ++i)
        for (int k = 0; k < around; ++k) {
            const double a = 2.0 * M_PI * k / around;
            m.points.emplace_back(float(length * i / (rings - 1)), float(radius * std::cos(a)),
                                  float(radius * std::sin(a)));
        }
    const uint32_t start = uint32_t(m.points.size()), end = start + 1;
    m.points.emplace_back(0.0f, 0.0f, 0.0f);
    m.points.emplace_back(float(length), 0.0f, 0.0f);
    auto at = [&](int i, int k) { return uint32_t(i * around + (k % around)); };
    for (int i = 0; i + 1 < rings; ++i)
        for (int k = 0; k < around; ++k) {
            m.triangles.emplace_back(at(i, k), at(i, k + 1), at(i + 1, k + 1));
            m.triangles.emplace_back(at(i, k), at(i + 1, k + 1), at(i + 1, k));
        }
    for (int k = 0; k < around; ++k) {
        m.triangles.emplace_back(start, at(0, k + 1), at(0, k));
        m.triangles.emplace_back(end, at(rings - 1, k), at(rings - 1, k + 1));
    }
    m.file = "tube.obj";
    analyzeTopology(m);
    return m;
}

/// `straight` (a tube from tube()) bent in the x-y plane by `angle` radians over its length, its
/// axis kept as long: a point at x turns by angle x / length about (0, length / angle).
inline Mesh bent(const Mesh& straight, double length, double angle)
{
    Mesh m = straight;
    const double rc = length / angle;
    for (Vec3f& p : m.points) {
        const double phi = angle * p.x() / length, r = rc - p.y();
        p = Vec3f(float(r * std::sin(phi)), float(rc - r * std::cos(phi)), p.z());
    }
    m.file = "bent.obj";
    return m;
}

/// A latitude-longitude sphere about `centre`: `rings` rings between the poles of `around`
/// vertices each, at radius `radius(direction)` (a constant for a sphere).
inline Mesh radialSphere(int rings, int around, const Vec3d& centre,
                         const std::function<double(const Vec3d&)>& radius, const char* file)
{
    Mesh m;
    auto add = [&](const Vec3d& d) {
        const Vec3d p = centre + radius(d) * d;
        m.points.emplace_back(float(p.x()), float(p.y()), float(p.z()));
    };
    add(Vec3d(0.0, 0.0, 1.0));
    for (int i = 1; i <= rings; ++i)
        for (int k = 0; k < around; ++k) {
            const double theta = M_PI * i / (rings + 1), phi = 2.0 * M_PI * k / around;
            add(Vec3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                      std::cos(theta)));
        }
    add(Vec3d(0.0, 0.0, -1.0));
    const uint32_t south = uint32_t(m.points.size() - 1);
    auto at = [&](int i, int k) { return uint32_t(1 + (i - 1) * around + (k % around)); };
    for (int k = 0; k < around; ++k) {
        m.triangles.emplace_back(0u, at(1, k), at(1, k + 1));
        m.triangles.emplace_back(south, at(rings, k + 1), at(rings, k));
    }
    for (int i = 1; i < rings; ++i)
        for (int k = 0; k < around; ++k) {
            m.triangles.emplace_back(at(i, k), at(i + 1, k), at(i + 1, k + 1));
            m.triangles.emplace_back(at(i, k), at(i + 1, k + 1), at(i, k + 1));
        }
    m.file = file;
    analyzeTopology(m);
    return m;
}

/// The cube of half-size `half` about `centre`, two triangles per face.
inline Mesh cube(double half, const Vec3d& centre)
{
    Mesh m;
    for (int i = 0; i < 8; ++i) {
        const Vec3d p = centre + half * Vec3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
        m.points.emplace_back(float(p.x()), float(p.y()), float(p.z()));
    }
    const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        m.triangles.emplace_back(q[0], q[1], q[2]);
        m.triangles.emplace_back(q[0], q[2], q[3]);
    }
    m.file = "cube.obj";
    analyzeTopology(m);
    return m;
}

/// The upper hemisphere of radius 1 without its pole's cap: `rings` latitude rings of `around`
/// vertices from near the pole to the equator (the equator is the boundary), a pole vertex, faces
/// outward.
inline Mesh dome(int rings, int around)
{
    Mesh m;
    m.points.emplace_back(0.0f, 1.0f, 0.0f);
    for (int i = 1; i <= rings; ++i) {
        const double polar = 0.5 * M_PI * i / rings;
        for (int k = 0; k < around; ++k) {
            const double a = 2.0 * M_PI * k / around;
            m.points.emplace_back(float(std::sin(polar) * std::cos(a)), float(std::cos(polar)),
                                  float(std::sin(polar) * std::sin(a)));
        }
    }
    auto v = [&](int i, int k) { return uint32_t(1 + (i - 1) * around + (k % around)); };
    for (int k = 0; k < around; ++k) m.triangles.emplace_back(0, v(1, k + 1), v(1, k));
    for (int i = 1; i < rings; ++i)
        for (int k = 0; k < around; ++k) {
            m.triangles.emplace_back(v(i, k), v(i, k + 1), v(i + 1, k + 1));
            m.triangles.emplace_back(v(i, k), v(i + 1, k + 1), v(i + 1, k));
        }
    m.file = "dome.obj";
    analyzeTopology(m);
    return m;
}

/// A square sheet of n x n quads over [-1, 1]^2 in x-z at height y = bump * exp(-2 r^2), facing +y:
/// one boundary loop, a grid unlike dome()'s rings.
inline Mesh bumpySheet(int n, double bump)
{
    Mesh m;
    for (int i = 0; i <= n; ++i)
        for (int k = 0; k <= n; ++k) {
            const double x = -1.0 + 2.0 * k / n, z = -1.0 + 2.0 * i / n;
            m.points.emplace_back(float(x), float(bump * std::exp(-2.0 * (x * x + z * z))),
                                  float(z));
        }
    auto v = [&](int i, int k) { return uint32_t(i * (n + 1) + k); };
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < n; ++k) {
            m.triangles.emplace_back(v(i, k), v(i + 1, k + 1), v(i, k + 1));
            m.triangles.emplace_back(v(i, k), v(i + 1, k), v(i + 1, k + 1));
        }
    m.file = "sheet.obj";
    analyzeTopology(m);
    return m;
}

} // namespace volmorph::test
