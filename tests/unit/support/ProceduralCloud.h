// The test data generator's procedural cumulus cloud (the unit tests' volume inputs, and issue 33's
// second scene against Cycles through volmorph_bench_cloud): a heap of spheres whose surface is
// displaced by fractal value noise, with a soft edge a few voxels wide and a noisy interior, and a
// temperature that falls with height. Deterministic: the same transform gives the same grids.
#pragma once

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace volmorph::test::cloud {

using openvdb::Vec3d;

/// A pseudo-random value in [0, 1) for a lattice point (a 32-bit integer hash).
inline double hashed(int x, int y, int z)
{
    uint32_t h = uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(z) * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return double(h & 0xffffffu) / double(0x1000000);
}

/// Value noise in [0, 1): the lattice values blended with a smoothstep in each axis.
inline double valueNoise(const Vec3d& p)
{
    const int x = int(std::floor(p.x())), y = int(std::floor(p.y())), z = int(std::floor(p.z()));
    auto fade = [](double t) { return t * t * (3.0 - 2.0 * t); };
    const double u = fade(p.x() - x), v = fade(p.y() - y), w = fade(p.z() - z);
    auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
    double c[2][2];
    for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k)
            c[j][k] = lerp(hashed(x, y + j, z + k), hashed(x + 1, y + j, z + k), u);
    return lerp(lerp(c[0][0], c[1][0], v), lerp(c[0][1], c[1][1], v), w);
}

/// Fractal noise: `octaves` of value noise, each twice the frequency and half the amplitude; about
/// [-0.5, 0.5].
inline double fbm(Vec3d p, int octaves)
{
    double sum = 0.0, amplitude = 0.5, norm = 0.0;
    for (int o = 0; o < octaves; ++o) {
        sum += amplitude * (valueNoise(p) - 0.5);
        norm += amplitude;
        amplitude *= 0.5;
        p = p * 2.03 + Vec3d(17.1, 5.3, 11.7);
    }
    return sum / norm;
}

/// Signed distance (world units) to the heap of spheres: negative inside.
inline double heap(const Vec3d& p)
{
    struct Ball {
        Vec3d c;
        double r;
    };
    static const Ball balls[] = {{{0.0, 0.35, 0.0}, 0.35},    {{-0.35, 0.25, 0.05}, 0.25},
                                 {{0.35, 0.27, -0.05}, 0.27}, {{0.1, 0.6, 0.05}, 0.25},
                                 {{-0.15, 0.5, -0.15}, 0.2},  {{0.05, 0.25, 0.25}, 0.22}};
    double d = 1e30;
    for (const Ball& b : balls) d = std::min(d, (p - b.c).length() - b.r);
    return std::max(d, 0.1 - p.y()); // a flat base
}

/// Density at world point p, 0..1: the heap displaced by noise (0.12 world units), a soft edge
/// 0.04 wide, and an interior modulated by finer noise.
inline float cloudDensity(const Vec3d& p)
{
    const double displaced = heap(p) + 0.12 * fbm(p * 4.0, 5);
    if (displaced > 0.04) return 0.0f;
    const double edge = std::clamp((0.04 - displaced) / 0.08, 0.0, 1.0);
    const double inside = std::clamp(0.75 + 1.2 * fbm(p * 9.0 + Vec3d(3.0), 3), 0.1, 1.0);
    return float(edge * edge * (3.0 - 2.0 * edge) * inside);
}

/// The temperature where the cloud has density: 1 at its base (y = 0) falling to 0 at y = 1.
inline float temperature(const Vec3d& p)
{
    return float(std::clamp(1.0 - p.y(), 0.0, 1.0));
}

/// The world box the cloud lies in (world units).
inline const openvdb::BBoxd kBounds(Vec3d(-0.9, -0.05, -0.6), Vec3d(0.9, 1.05, 0.6));

/// The cloud sampled at the voxels of `xform` (any linear transform: another voxel size, a
/// rotation) that lie in the box's image: grid "density" (fog, 0..1) and, when `temperatureGrid`
/// is given, "temperature" at the same voxels.
inline openvdb::FloatGrid::Ptr make(const openvdb::math::Transform::Ptr& xform,
                                    openvdb::FloatGrid::Ptr* temperatureGrid = nullptr)
{
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(xform);
    openvdb::FloatGrid::Ptr heat = openvdb::FloatGrid::create(0.0f);
    heat->setName("temperature");
    heat->setTransform(xform);
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (int c = 0; c < 8; ++c) {
        const Vec3d w((c & 1) ? kBounds.max().x() : kBounds.min().x(),
                      (c & 2) ? kBounds.max().y() : kBounds.min().y(),
                      (c & 4) ? kBounds.max().z() : kBounds.min().z());
        const Vec3d i = xform->worldToIndex(w);
        lo = openvdb::math::minComponent(lo, i);
        hi = openvdb::math::maxComponent(hi, i);
    }
    openvdb::FloatGrid::Accessor acc = grid->getAccessor(), hot = heat->getAccessor();
    for (int i = int(std::floor(lo.x())); i <= int(std::ceil(hi.x())); ++i)
        for (int j = int(std::floor(lo.y())); j <= int(std::ceil(hi.y())); ++j)
            for (int k = int(std::floor(lo.z())); k <= int(std::ceil(hi.z())); ++k) {
                const Vec3d p = grid->indexToWorld(openvdb::Coord(i, j, k));
                const float rho = cloudDensity(p);
                if (!(rho > 0.0f)) continue;
                acc.setValue(openvdb::Coord(i, j, k), rho);
                if (temperatureGrid) hot.setValue(openvdb::Coord(i, j, k), temperature(p));
            }
    if (temperatureGrid) *temperatureGrid = heat;
    return grid;
}

} // namespace volmorph::test::cloud
