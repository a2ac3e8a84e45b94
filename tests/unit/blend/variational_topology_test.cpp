// Issue 40's checks on shape and topology, on the variational function's slices at 21 times (the
// dense solve, 2 x 300 surface points per shape, time_scale 0.25, slices every 0.04 world units
// over a box clear of both shapes), each slice's zero set meshed by OpenVDB's volumeToMesh and
// counted: a sphere into two separate spheres goes from one closed shell to two and never shows
// another piece; a sphere into a torus goes from Euler characteristic 2 to 0 once.
#include "blend/variational/Constraints.h"
#include "blend/variational/Interpolant.h"
#include "blend/variational/Slice.h"
#include "support/ZeroSetTopology.h"

#include <gtest/gtest.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>

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

openvdb::FloatGrid::Ptr torus(double R, double r)
{
    return volmorph::test::torusLevelSet(R, r, kVoxel);
}

Interpolant morph(const openvdb::FloatGrid& from, const openvdb::FloatGrid& to)
{
    std::vector<Constraint> c = sampleConstraints(from, 300, kVoxel, 0.0);
    const std::vector<Constraint> e = sampleConstraints(to, 300, kVoxel, kTimeScale);
    c.insert(c.end(), e.begin(), e.end());
    return Interpolant::solveDense(c);
}

using volmorph::test::Topology;

Topology topologyAt(const Interpolant& f, double t)
{
    const auto transform = openvdb::math::Transform::createLinearTransform(kSliceVoxel);
    const openvdb::CoordBBox box(openvdb::Coord(-18), openvdb::Coord(18)); // +-0.72 world units
    const auto grid =
        sliceOverBox([&](const Point4& p) { return f(p); }, t * kTimeScale, transform, box);
    return volmorph::test::topologyOf(*grid);
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
// measured 0.0027 at t = 0.5 and 0.0127 at 0.8, just after the split; every 4 voxels gave 0.026
// and 0.15, trilinear 0.14 and 0.95), from a thirtieth of the evaluations (11,038 and 12,414).
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
        EXPECT_LT(evaluations * 20, size_t(box.volume()));
    }
}
