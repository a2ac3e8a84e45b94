// A procedural cumulus cloud as a fog .vdb (issue 33's second scene against Cycles): a heap of
// spheres whose surface is displaced by fractal value noise, with a soft edge a few voxels wide and
// a noisy interior. Deterministic: the same arguments give the same file.
// usage: volmorph_bench_cloud OUT.vdb [VOXEL_SIZE (world units, default 0.01)]
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace {

using openvdb::Vec3d;

/// A pseudo-random value in [0, 1) for a lattice point (a 32-bit integer hash).
double hashed(int x, int y, int z)
{
    uint32_t h = uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(z) * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return double(h & 0xffffffu) / double(0x1000000);
}

/// Value noise in [0, 1): the lattice values blended with a smoothstep in each axis.
double valueNoise(const Vec3d& p)
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
double fbm(Vec3d p, int octaves)
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
double heap(const Vec3d& p)
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
float cloudDensity(const Vec3d& p)
{
    const double displaced = heap(p) + 0.12 * fbm(p * 4.0, 5);
    if (displaced > 0.04) return 0.0f;
    const double edge = std::clamp((0.04 - displaced) / 0.08, 0.0, 1.0);
    const double inside = std::clamp(0.75 + 1.2 * fbm(p * 9.0 + Vec3d(3.0), 3), 0.1, 1.0);
    return float(edge * edge * (3.0 - 2.0 * edge) * inside);
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s OUT.vdb [VOXEL_SIZE]\n", argv[0]);
        return 2;
    }
    const double voxel = argc > 2 ? std::atof(argv[2]) : 0.01;
    if (!(voxel > 0.0)) {
        std::fprintf(stderr, "%s: the voxel size must be a positive number\n", argv[0]);
        return 2;
    }
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    const int x0 = int(std::floor(-0.9 / voxel)), x1 = int(std::ceil(0.9 / voxel));
    const int y0 = int(std::floor(-0.05 / voxel)), y1 = int(std::ceil(1.05 / voxel));
    const int z0 = int(std::floor(-0.6 / voxel)), z1 = int(std::ceil(0.6 / voxel));
    openvdb::FloatGrid::Accessor acc = grid->getAccessor();
    for (int i = x0; i <= x1; ++i)
        for (int j = y0; j <= y1; ++j)
            for (int k = z0; k <= z1; ++k) {
                const float rho = cloudDensity(grid->indexToWorld(openvdb::Coord(i, j, k)));
                if (rho > 0.0f) acc.setValue(openvdb::Coord(i, j, k), rho);
            }
    openvdb::io::File(argv[1]).write({grid});
    std::printf("%s: %zu active voxels, voxel %g\n", argv[1], size_t(grid->activeVoxelCount()),
                voxel);
    return 0;
}
