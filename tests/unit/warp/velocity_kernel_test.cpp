// The velocity's vector kernel (warp/VelocityKernel.h) against InverseWarp::derivatives and
// ::velocity, its second method: random pairs of every type, both weightings, points far from and
// close to the elements, a scene far from the world's origin; and its builds against each other,
// bit for bit.
#include "support/WarpFixtures.h"

#include "warp/VelocityKernel.h"

#include <cstring>

using namespace volmorph;
using namespace volmorph::test;

namespace {

/// Random pairs over a cube of `extent`, moved by `shift`; inverse-square (epsilon 0.5) or
/// Beier-Neely weights by trial.
struct Trial {
    std::vector<FeaturePairSpec> pairs;
    WarpSpec spec;
};
Trial trial(std::mt19937& random, int index, double extent, const Vec3d& shift)
{
    Trial out;
    out.pairs = randomPairs(random, 1 + index % 20, extent);
    for (FeaturePairSpec& p : out.pairs) {
        p.source.origin += shift;
        p.target.origin += shift;
    }
    out.spec.epsilon = 0.5;
    if (index % 3 == 2) {
        out.spec.weighting = Weighting::BeierNeely;
        out.spec.a = 0.5;
        out.spec.b = 2.0;
        out.spec.p = 0.5;
    }
    return out;
}

/// Both sides' velocities at p by InverseWarp (double precision); false at a fold.
bool scalarVelocities(const InverseWarp& warp, const Vec3d& p, Vec3d v[2])
{
    InverseWarp::Derivatives d[2];
    warp.derivatives(p, d[0], d[1]);
    const bool s = InverseWarp::velocity(d[0], v[0]);
    const bool t = InverseWarp::velocity(d[1], v[1]);
    return s && t;
}

} // namespace

TEST(VelocityKernel, EqualsTheScalarVelocityInSinglePrecision)
{
    // 1 to 20 pairs, a cube of 100 voxels, 40 points per warp (5 batches of 8); half the points
    // near an element's origin (within a few voxels: near pairs dominate, some go to the double
    // path). Relative error of each side's velocity; where det J < 0.1, times det J.
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const Vec3d& shift : {Vec3d(0.0), Vec3d(4e4, -3e4, 2e4)}) {
        double worst = 0.0, worstNearFolds = 0.0; // the latter times det J
        for (int index = 0; index < 60; ++index) {
            const Trial c = trial(random, index, 100.0, shift);
            const double t = 0.05 + 0.9 * u(random);
            const InverseWarp warp(c.pairs, c.spec, t);
            const detail::VelocityKernel kernel(warp, 1.0);
            std::vector<Vec3d> points(40), vs(40), vt(40);
            bool regular[40];
            for (size_t k = 0; k < points.size(); ++k) {
                points[k] = shift + Vec3d(u(random), u(random), u(random)) * 120.0 - Vec3d(10.0);
                if (k % 2)
                    points[k] = warp.interpolated(random() % warp.pairCount()).origin +
                                (Vec3d(u(random), u(random), u(random)) - Vec3d(0.5)) * 6.0;
            }
            kernel.velocities(points.data(), points.size(), vs.data(), vt.data(), regular);
            for (size_t k = 0; k < points.size(); ++k) {
                Vec3d v[2];
                EXPECT_EQ(scalarVelocities(warp, points[k], v), regular[k]);
                const double e = std::max((vs[k] - v[0]).length() / v[0].length(),
                                          (vt[k] - v[1]).length() / v[1].length());
                // J's inverse magnifies the sums' rounding by J's condition: near a fold
                // (det J -> 0) the error grows as 1 / det.
                InverseWarp::Derivatives d[2];
                warp.derivatives(points[k], d[0], d[1]);
                const double det =
                    std::min(std::abs(d[0].jacobian.det()), std::abs(d[1].jacobian.det()));
                (det >= 0.1 ? worst : worstNearFolds) =
                    std::max(det >= 0.1 ? worst : worstNearFolds, e * std::min(det, 1.0));
            }
        }
        // Single precision: about 1e-7 relative per operation, the quotient rule's subtractions
        // of displacements and J's inverse; 1e-4 is a hundredth of the velocity's own 1% bound.
        EXPECT_LT(worst, 1e-4) << "shifted by " << shift;
        EXPECT_LT(worstNearFolds, 5e-5) << "shifted by " << shift;
        EXPECT_GT(worst, 0.0) << "the kernel ran (it is not the scalar path)";
    }
}

TEST(VelocityKernel, OnAnElementItIsTheScalarPath)
{
    // epsilon 0: a point on an element is that pair's map alone (InverseWarp::kOnElement).
    std::mt19937 random(9);
    WarpSpec spec;
    spec.epsilon = 0.0;
    const auto pairs = randomPairs(random, 5, 50.0);
    const InverseWarp warp(pairs, spec, 0.3);
    const detail::VelocityKernel kernel(warp, 1.0);
    const Vec3d p = warp.interpolated(2).origin;
    Vec3d v[2], ks, kt;
    bool regular = false;
    const bool scalar = scalarVelocities(warp, p, v);
    kernel.velocities(&p, 1, &ks, &kt, &regular);
    EXPECT_EQ(regular, scalar);
    EXPECT_EQ(std::memcmp(&v[0], &ks, sizeof ks), 0);
    EXPECT_EQ(std::memcmp(&v[1], &kt, sizeof kt), 0);
}

TEST(VelocityKernel, VectorAndBaselineBuildsGiveTheSameBits)
{
    if (detail::bestKernelBuild() == detail::KernelBuild::Baseline)
        GTEST_SKIP() << "no vector build here (GCC on x86-64 with AVX2 only)";
    std::mt19937 random(13);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int index = 0; index < 12; ++index) {
        const Trial c = trial(random, index, 100.0, Vec3d(0.0));
        const InverseWarp warp(c.pairs, c.spec, 0.4);
        const detail::VelocityKernel baseline(warp, 1.0, detail::KernelBuild::Baseline);
        for (const detail::KernelBuild build :
             {detail::KernelBuild::Avx2, detail::KernelBuild::Avx512}) {
            if (int(detail::bestKernelBuild()) < int(build)) continue; // not on this CPU
            const detail::VelocityKernel vector(warp, 1.0, build);
            // 50 points in one call, and each alone: a point's bits do not depend on its batch.
            std::vector<Vec3d> points(50), a(100), b(100), alone(2);
            bool ra[50], rb[50], r1;
            for (Vec3d& p : points)
                p = Vec3d(u(random), u(random), u(random)) * 120.0 - Vec3d(10.0);
            baseline.velocities(points.data(), 50, a.data(), a.data() + 50, ra);
            vector.velocities(points.data(), 50, b.data(), b.data() + 50, rb);
            EXPECT_EQ(std::memcmp(a.data(), b.data(), 100 * sizeof(Vec3d)), 0)
                << "build " << int(build);
            EXPECT_EQ(std::memcmp(ra, rb, sizeof ra), 0);
            for (int k = 0; k < 50; k += 7) {
                vector.velocities(&points[k], 1, &alone[0], &alone[1], &r1);
                EXPECT_EQ(std::memcmp(&alone[0], &a[k], sizeof(Vec3d)), 0);
                EXPECT_EQ(std::memcmp(&alone[1], &a[50 + k], sizeof(Vec3d)), 0);
            }
        }
    }
}

TEST(VelocityKernel, ItsJetsAreTheScalarMapAndJacobianInSinglePrecision)
{
    // What TimedWarp blends between its levels: each side's point and dW/dp'.
    std::mt19937 random(13);
    WarpSpec spec;
    spec.epsilon = 2.0;
    const auto pairs = randomPairs(random, 6, 50.0);
    const InverseWarp warp(pairs, spec, 0.4);
    const detail::VelocityKernel kernel(warp, 1.0);
    std::uniform_real_distribution<double> u(0.0, 50.0);
    std::vector<Vec3d> points(37); // not a multiple of 8
    for (Vec3d& p : points) p = Vec3d(u(random), u(random), u(random));
    std::vector<detail::VelocityKernel::Jet> jets(points.size());
    kernel.jets(points.data(), points.size(), jets.data());
    for (size_t i = 0; i < points.size(); ++i) {
        Vec3d s[2];
        InverseWarp::Derivatives d[2];
        warp.map(points[i], s[0], s[1]);
        warp.derivatives(points[i], d[0], d[1]);
        for (int side = 0; side < 2; ++side) {
            EXPECT_LT((jets[i].point[side] - s[side]).length(), 1e-4 * 50.0) << i;
            InverseWarp::Derivatives k;
            k.jacobian = jets[i].jacobian[side];
            k.rate = d[side].rate;
            EXPECT_LT(relativeError(k, d[side]), 1e-4) << i << " side " << side;
        }
    }
}
