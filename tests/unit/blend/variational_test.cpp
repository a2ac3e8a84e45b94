// The variational implicit function (blend/variational/, issue 40) against what it must be: the
// dense solve passes through its constraints and reproduces a linear function exactly, its
// gradient is the derivative of its values, a sphere's constraints at t = 0 and t = 1 give that
// sphere at every t between, a sphere into a larger concentric one grows monotonically, and the
// constraints cover the surface evenly, on it, their partners inside.
#include "blend/variational/Constraints.h"
#include "blend/variational/Interpolant.h"
#include "blend/variational/PartitionOfUnity.h"

#include <gtest/gtest.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cstdio>
#include <random>

using namespace volmorph::detail::variational;

namespace {

openvdb::FloatGrid::Ptr sphere(double radius, double voxel, double x = 0.0)
{
    openvdb::initialize();
    return openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(radius), openvdb::Vec3f(float(x), 0.0f, 0.0f), float(voxel), 3.0f);
}

/// The zero of f along the ray from `from` in `direction` at fourth coordinate w, by bisection
/// over [0, reach] (f > 0 inside); -1 when f has one sign at both ends.
template <typename F>
double radiusAlong(const F& f, const Eigen::Vector3d& direction, double w, double reach,
                   const Eigen::Vector3d& from = Eigen::Vector3d::Zero())
{
    const auto at = [&](double s) {
        const Eigen::Vector3d p = from + s * direction;
        return f(Point4(p.x(), p.y(), p.z(), w));
    };
    if ((at(0.0) > 0.0) == (at(reach) > 0.0)) return -1.0;
    double lo = 0.0, hi = reach;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (at(mid) > 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

std::vector<Eigen::Vector3d> directions(int n)
{
    std::mt19937 rng(7);
    std::normal_distribution<double> normal;
    std::vector<Eigen::Vector3d> d;
    for (int i = 0; i < n; ++i)
        d.push_back(Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized());
    return d;
}

/// f's gradient by central differences of step h.
template <typename F>
Point4 centralDifferences(const F& f, const Point4& p, double h)
{
    Point4 g;
    for (int k = 0; k < 4; ++k) {
        Point4 a = p, b = p;
        a[k] -= h, b[k] += h;
        g[k] = (f(b) - f(a)) / (2 * h);
    }
    return g;
}

} // namespace

TEST(Variational, DenseSolvePassesThroughItsConstraints)
{
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Constraint> c;
    for (int i = 0; i < 300; ++i) c.push_back({Point4(u(rng), u(rng), u(rng), u(rng)), u(rng)});
    const Interpolant f = Interpolant::solveDense(c);
    double worst = 0.0;
    for (const Constraint& k : c) worst = std::max(worst, std::abs(f(k.point) - k.value));
    EXPECT_LT(worst, 1e-9);
    // The side conditions: the weights sum to zero and have no first moment.
    EXPECT_NEAR(f.weights().sum(), 0.0, 1e-9);
}

TEST(Variational, ALinearFunctionIsReproducedEverywhere)
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Point4 slope(0.3, -1.2, 0.7, 2.0);
    std::vector<Constraint> c;
    for (int i = 0; i < 100; ++i) {
        const Point4 p(u(rng), u(rng), u(rng), u(rng));
        c.push_back({p, 0.25 + slope.dot(p)});
    }
    const Interpolant f = Interpolant::solveDense(c);
    for (int i = 0; i < 50; ++i) {
        const Point4 p(2 * u(rng), 2 * u(rng), 2 * u(rng), 2 * u(rng));
        EXPECT_NEAR(f(p), 0.25 + slope.dot(p), 1e-8);
        EXPECT_LT((f.gradient(p) - slope).norm(), 1e-7);
    }
}

TEST(Variational, GradientIsTheDerivative)
{
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Constraint> c;
    for (int i = 0; i < 80; ++i) c.push_back({Point4(u(rng), u(rng), u(rng), u(rng)), u(rng)});
    const Interpolant f = Interpolant::solveDense(c);
    const double h = 1e-5;
    for (int i = 0; i < 20; ++i) {
        const Point4 p(u(rng), u(rng), u(rng), u(rng));
        const Point4 g = f.gradient(p), differences = centralDifferences(f, p, h);
        for (int k = 0; k < 4; ++k)
            EXPECT_NEAR(g[k], differences[k], 1e-5 * (1.0 + std::abs(g[k])));
    }
}

// The AVX2 build of the sums and the SSE2 one give the same bits (frames do not depend on the
// machine's vector unit).
TEST(Variational, BothBuildsOfTheSumsAgreeBitForBit)
{
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 here: one build only";
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Constraint> c;
    for (int i = 0; i < 203; ++i) c.push_back({Point4(u(rng), u(rng), u(rng), u(rng)), u(rng)});
    const Interpolant f = Interpolant::solveDense(c);
    for (int i = 0; i < 1000; ++i) {
        const Point4 p(u(rng), u(rng), u(rng), u(rng));
        Point4 g, h;
        ASSERT_EQ(f.evaluate(p, &g), f.evaluateBaseline(p, &h));
        for (int k = 0; k < 4; ++k) ASSERT_EQ(g[k], h[k]);
        ASSERT_EQ(f.evaluate(p, nullptr), f.evaluateBaseline(p, nullptr));
    }
}

TEST(Variational, ConstraintsLieOnTheSurfaceEvenly)
{
    const double voxel = 0.02, radius = 0.5;
    const auto grid = sphere(radius, voxel);
    const std::vector<Constraint> c = sampleConstraints(*grid, 500, 1.0 * voxel, 0.25);
    const size_t k = kConstraintsPerPoint;
    ASSERT_GE(c.size(), k * 450u);
    ASSERT_LE(c.size(), k * 500u);
    double nearest = 1e9, farthest = 0.0;
    for (size_t i = 0; i < c.size(); i += k) {
        EXPECT_NEAR(c[i].point.head<3>().norm(), radius, 0.05 * voxel);
        EXPECT_NEAR(c[i + 1].point.head<3>().norm(), radius - voxel, 0.05 * voxel);
        EXPECT_NEAR(c[i + 2].point.head<3>().norm(), radius + voxel, 0.05 * voxel);
        EXPECT_EQ(c[i].value, 0.0);
        // The sphere's own distances there, a voxel in and out.
        EXPECT_NEAR(c[i + 1].value, voxel, 0.05 * voxel);
        EXPECT_NEAR(c[i + 2].value, -voxel, 0.05 * voxel);
        EXPECT_EQ(c[i].point[3], 0.25);
        // Spacing: each point's nearest neighbour.
        double d = 1e9;
        for (size_t j = 0; j < c.size(); j += k)
            if (j != i) d = std::min(d, (c[i].point - c[j].point).norm());
        nearest = std::min(nearest, d);
        farthest = std::max(farthest, d);
    }
    // Evenly: 500 points on a sphere of area pi are about 0.079 apart; none crowded, no gap.
    const double spacing = std::sqrt(4.0 * M_PI * radius * radius / double(c.size() / k));
    EXPECT_GT(nearest, 0.2 * spacing);
    EXPECT_LT(farthest, 2.0 * spacing);
}

// The time axis's scale shapes the in-betweens (the function is smooth across the ends, so
// far-apart ends bulge between and overshoot past them): with the ends 0.25 world units apart in t,
// about half a sphere's radius, a sphere into a sphere of twice the radius grows monotonically and
// one into itself bulges by under 2%; with them 1 apart (two radii) the growth overshoots the end
// by 0.2% and the bulge is 20% (session 33's probe, BENCHMARKS.md).
constexpr double kTimeScale = 0.25;

TEST(Variational, ASphereIntoItselfIsSymmetricAndExactAtTheEnds)
{
    const double voxel = 0.02, radius = 0.5;
    const auto grid = sphere(radius, voxel);
    std::vector<Constraint> c = sampleConstraints(*grid, 300, voxel, 0.0);
    const std::vector<Constraint> end = sampleConstraints(*grid, 300, voxel, kTimeScale);
    c.insert(c.end(), end.begin(), end.end());
    const Interpolant f = Interpolant::solveDense(c);
    for (const Eigen::Vector3d& d : directions(20)) {
        EXPECT_NEAR(radiusAlong(f, d, 0.0, 2.0), radius, 0.25 * voxel);
        EXPECT_NEAR(radiusAlong(f, d, kTimeScale, 2.0), radius, 0.25 * voxel);
        for (double t : {0.1, 0.3, 0.5}) {
            const double r = radiusAlong(f, d, t * kTimeScale, 2.0);
            EXPECT_NEAR(r, radiusAlong(f, d, (1.0 - t) * kTimeScale, 2.0), 1e-6);
            EXPECT_GE(r, radius - 0.25 * voxel);
            EXPECT_LT(r, 1.02 * radius);
        }
    }
}

TEST(Variational, ASphereIntoALargerOneGrowsMonotonically)
{
    const double voxel = 0.02;
    std::vector<Constraint> c = sampleConstraints(*sphere(0.3, voxel), 300, voxel, 0.0);
    const std::vector<Constraint> end =
        sampleConstraints(*sphere(0.6, voxel), 300, voxel, kTimeScale);
    c.insert(c.end(), end.begin(), end.end());
    const Interpolant f = Interpolant::solveDense(c);
    for (const Eigen::Vector3d& d : directions(20)) {
        double previous = 0.0;
        for (int k = 0; k <= 20; ++k) {
            const double r = radiusAlong(f, d, 0.05 * k * kTimeScale, 2.0);
            EXPECT_GT(r, previous) << "t = " << 0.05 * k;
            previous = r;
        }
        EXPECT_NEAR(radiusAlong(f, d, 0.0, 2.0), 0.3, 0.25 * voxel);
        EXPECT_NEAR(radiusAlong(f, d, kTimeScale, 2.0), 0.6, 0.25 * voxel);
    }
}

TEST(Variational, ConstraintsInOneHyperplaneAreRefused)
{
    // All at w = 0: the polynomial's t coefficient is undetermined.
    std::vector<Constraint> c;
    for (int i = 0; i < 20; ++i)
        c.push_back({Point4(std::cos(i), std::sin(i), 0.1 * i, 0.0), double(i % 3)});
    EXPECT_THROW(Interpolant::solveDense(c), std::invalid_argument);
    EXPECT_EQ(denseSolveBytes(995), 2u * 1000u * 1000u * 8u);
}

// The two-level partition of unity against the dense solve of the same constraints: where the
// zero sets lie (along rays at t = 0.25, 0.5, 0.75), on a sphere growing and on a sphere becoming
// two (where the in-betweens lie away from every constraint), 2 x 1000 constraints, a coarse level
// of 500: within 0.1 voxel (issue 40's bound for a solver of another system).
TEST(Variational, PartitionOfUnityPutsTheZeroSetWhereTheDenseSolveDoes)
{
    const double voxel = 0.02;
    auto twoSpheres = sphere(0.25, voxel, -0.35);
    openvdb::tools::csgUnion(*twoSpheres, *sphere(0.25, voxel, 0.35));
    for (const auto& end : {sphere(0.6, voxel), twoSpheres}) {
        std::vector<Constraint> c = sampleConstraints(*sphere(0.3, voxel), 500, voxel, 0.0);
        const std::vector<Constraint> e = sampleConstraints(*end, 500, voxel, kTimeScale);
        c.insert(c.end(), e.begin(), e.end());
        const Interpolant dense = Interpolant::solveDense(c);
        PartitionOptions options;
        options.coarse = 500;
        const PartitionOfUnity pu = PartitionOfUnity::solve(c, options);
        EXPECT_GT(pu.patchCount(), 50u);
        double worst = 0.0;
        int rays = 0;
        const std::vector<Eigen::Vector3d> ds = directions(60);
        for (double t : {0.25, 0.5, 0.75})
            for (size_t i = 0; i < ds.size(); ++i) {
                const Eigen::Vector3d from(end == twoSpheres ? (i % 2 ? 0.35 : -0.35) : 0.0, 0, 0);
                const double a = radiusAlong(dense, ds[i], t * kTimeScale, 0.7, from);
                const double b = radiusAlong(pu, ds[i], t * kTimeScale, 0.7, from);
                ASSERT_EQ(a < 0.0, b < 0.0) << "a crossing only one of them has, t = " << t;
                if (a < 0.0) continue;
                worst = std::max(worst, std::abs(a - b) / voxel);
                ++rays;
            }
        EXPECT_GT(rays, 150);
        EXPECT_LT(worst, 0.1);
        std::printf("partition of unity vs dense: zero sets at most %.4f voxel apart (%d rays)\n",
                    worst, rays);
    }
}

// The partition of unity's gradient (the weights' derivatives included) against central
// differences of its values, at points near the shapes and between them, at three times.
TEST(Variational, PartitionOfUnityGradientIsTheDerivative)
{
    const double voxel = 0.02;
    auto twoSpheres = sphere(0.25, voxel, -0.35);
    openvdb::tools::csgUnion(*twoSpheres, *sphere(0.25, voxel, 0.35));
    std::vector<Constraint> c = sampleConstraints(*sphere(0.3, voxel), 500, voxel, 0.0);
    const std::vector<Constraint> e = sampleConstraints(*twoSpheres, 500, voxel, kTimeScale);
    c.insert(c.end(), e.begin(), e.end());
    PartitionOptions options;
    options.coarse = 500;
    const PartitionOfUnity pu = PartitionOfUnity::solve(c, options);
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(-0.6, 0.6);
    const double h = 1e-6;
    for (int i = 0; i < 60; ++i) {
        const Point4 p(u(rng), u(rng) / 2, u(rng) / 2, kTimeScale * (i % 3) / 2.0);
        const Point4 g = pu.gradient(p), differences = centralDifferences(pu, p, h);
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(g[k], differences[k], 1e-4 * (1.0 + g.norm())) << k;
    }
}
