// Issue 40's checks on shape and topology, on the variational function's slices at 21 times (the
// dense solve, 2 x 300 surface points per shape, time_scale 0.25, slices every 0.04 world units
// over a box clear of both shapes), each slice's zero set meshed by OpenVDB's volumeToMesh and
// counted: a sphere into two separate spheres goes from one closed shell to two and never shows
// another piece; a sphere into a torus goes from Euler characteristic 2 to 0 once.
#include "blend/variational/Constraints.h"
#include "blend/variational/Interpolant.h"
#include "blend/variational/Slice.h"

#include <gtest/gtest.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <cmath>
#include <array>
#include <cstdio>
#include <numeric>
#include <set>

using namespace volmorph::detail::variational;

namespace {

constexpr double kVoxel = 0.02, kSliceVoxel = 0.04, kTimeScale = 0.25;

openvdb::FloatGrid::Ptr sphere(double radius, double x = 0.0)
{
    openvdb::initialize();
    return openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(radius), openvdb::Vec3f(float(x), 0.0f, 0.0f), float(kVoxel), 3.0f);
}

/// A torus about the y axis (major radius R, tube radius r): its exact signed distance in a band.
openvdb::FloatGrid::Ptr torus(double R, double r)
{
    const float band = float(3.0 * kVoxel);
    auto grid = openvdb::FloatGrid::create(band);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(kVoxel));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    auto acc = grid->getAccessor();
    const int n = int(std::ceil((R + r) / kVoxel)) + 4;
    for (int i = -n; i <= n; ++i)
        for (int j = -n; j <= n; ++j)
            for (int k = -n; k <= n; ++k) {
                const double x = i * kVoxel, y = j * kVoxel, z = k * kVoxel;
                const double d = std::hypot(std::hypot(x, z) - R, y) - r;
                if (std::abs(d) < band) acc.setValue(openvdb::Coord(i, j, k), float(d));
            }
    return grid;
}

Interpolant morph(const openvdb::FloatGrid& from, const openvdb::FloatGrid& to)
{
    std::vector<Constraint> c = sampleConstraints(from, 300, kVoxel, 0.0);
    const std::vector<Constraint> e = sampleConstraints(to, 300, kVoxel, kTimeScale);
    c.insert(c.end(), e.begin(), e.end());
    return Interpolant::solveDense(c);
}

struct Topology {
    int components = 0;
    long euler = 0; ///< V - E + F of the triangulated zero set
};

Topology topologyAt(const Interpolant& f, double t)
{
    const auto transform = openvdb::math::Transform::createLinearTransform(kSliceVoxel);
    const openvdb::CoordBBox box(openvdb::Coord(-18), openvdb::Coord(18)); // +-0.72 world units
    const auto grid =
        sliceOverBox([&](const Point4& p) { return f(p); }, t * kTimeScale, transform, box);
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0);
    std::vector<std::array<uint32_t, 3>> faces;
    for (const auto& tri : triangles) faces.push_back({tri[0], tri[1], tri[2]});
    for (const auto& q : quads) {
        faces.push_back({q[0], q[1], q[2]});
        faces.push_back({q[0], q[2], q[3]});
    }
    std::vector<uint32_t> parent(points.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    std::set<std::pair<uint32_t, uint32_t>> edges;
    for (const auto& face : faces)
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = face[e], b = face[(e + 1) % 3];
            edges.insert({std::min(a, b), std::max(a, b)});
            parent[root(a)] = root(b);
        }
    Topology topology;
    for (uint32_t v = 0; v < parent.size(); ++v) topology.components += root(v) == v;
    topology.euler = long(points.size()) - long(edges.size()) + long(faces.size());
    return topology;
}

} // namespace

TEST(VariationalTopology, ASphereIntoTwoSpheresSplitsOnceIntoTwoShells)
{
    auto two = sphere(0.25, -0.35);
    openvdb::tools::csgUnion(*two, *sphere(0.25, 0.35));
    const Interpolant f = morph(*sphere(0.3), *two);
    int previous = 1, splits = 0;
    for (int k = 0; k <= 20; ++k) {
        const Topology topology = topologyAt(f, 0.05 * k);
        std::printf("t %.2f: %d shells, Euler %ld\n", 0.05 * k, topology.components,
                    topology.euler);
        ASSERT_GE(topology.components, 1);
        ASSERT_LE(topology.components, 2) << "t = " << 0.05 * k;
        EXPECT_EQ(topology.euler, 2L * topology.components) << "t = " << 0.05 * k; // spheres
        splits += topology.components != previous;
        previous = topology.components;
    }
    EXPECT_EQ(topologyAt(f, 0.0).components, 1);
    EXPECT_EQ(previous, 2);
    EXPECT_EQ(splits, 1);
}

TEST(VariationalTopology, ASphereIntoATorusOpensItsHoleOnce)
{
    const Interpolant f = morph(*sphere(0.3), *torus(0.35, 0.12));
    long previous = 2;
    int changes = 0;
    for (int k = 0; k <= 20; ++k) {
        const Topology topology = topologyAt(f, 0.05 * k);
        std::printf("t %.2f: %d shells, Euler %ld\n", 0.05 * k, topology.components,
                    topology.euler);
        EXPECT_EQ(topology.components, 1) << "t = " << 0.05 * k;
        EXPECT_TRUE(topology.euler == 2 || topology.euler == 0) << "t = " << 0.05 * k;
        changes += topology.euler != previous;
        previous = topology.euler;
    }
    EXPECT_EQ(previous, 0);
    EXPECT_EQ(changes, 1);
}

// The slice near its zero set from exact values every 2 voxels, tricubic between (sliceNearZero),
// against the slice evaluated at every voxel: every voxel within 1.5 voxels of the zero set is
// there, and its value is the exact one to 0.1 voxel (of the distance the local slope gives:
// measured 0.0016 at t = 0.5 and 0.0084 at 0.8, just after the split; every 4 voxels gave 0.026
// and 0.15, trilinear 0.14 and 0.95), from an eighth of the evaluations.
TEST(VariationalTopology, TheSliceNearItsZeroSetFromACoarseLatticeIsTheExactOne)
{
    auto two = sphere(0.25, -0.35);
    openvdb::tools::csgUnion(*two, *sphere(0.25, 0.35));
    const Interpolant f = morph(*sphere(0.3), *two);
    const auto fn = [&](const Point4& p) { return f(p); };
    const auto transform = openvdb::math::Transform::createLinearTransform(kVoxel);
    const openvdb::CoordBBox box(openvdb::Coord(-36), openvdb::Coord(36));
    for (double t : {0.5, 0.8}) {
        const auto exact = sliceOverBox(fn, t * kTimeScale, transform, box);
        const NearZeroSlice slice = sliceNearZero([&](const Point4& p, double*) { return f(p); },
                                                  t * kTimeScale, transform, box, 2, 1.5);
        const auto& near = slice.values;
        const size_t evaluations = slice.evaluations;
        auto e = exact->getConstAccessor();
        auto n = near->getConstAccessor();
        double worst = 0.0;
        size_t checked = 0;
        for (auto it = exact->cbeginValueOn(); it; ++it) {
            const openvdb::Coord c = it.getCoord();
            if (!box.isInside(c.offsetBy(-1)) || !box.isInside(c.offsetBy(1))) continue;
            const double slope =
                openvdb::Vec3d(e.getValue(c.offsetBy(1, 0, 0)) - e.getValue(c.offsetBy(-1, 0, 0)),
                               e.getValue(c.offsetBy(0, 1, 0)) - e.getValue(c.offsetBy(0, -1, 0)),
                               e.getValue(c.offsetBy(0, 0, 1)) - e.getValue(c.offsetBy(0, 0, -1)))
                    .length() /
                2.0; // per voxel
            if (std::abs(*it) > 1.5 * slope) continue;
            ASSERT_TRUE(n.isValueOn(c)) << "t = " << t << " " << c;
            worst = std::max(worst, std::abs(double(n.getValue(c)) - *it) / slope);
            ++checked;
        }
        std::printf("t %.1f: %zu voxels near the zero set, within %.4f voxel; %zu exact values "
                    "(the box has %llu voxels), %llu kept\n",
                    t, checked, worst, evaluations, (unsigned long long)box.volume(),
                    (unsigned long long)near->activeVoxelCount());
        EXPECT_GT(checked, 1000u);
        EXPECT_LT(worst, 0.1);
        EXPECT_LT(evaluations * 7, size_t(box.volume()));
    }
}
