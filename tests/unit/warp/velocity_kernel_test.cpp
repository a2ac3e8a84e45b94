// The velocity's vector kernel (warp/VelocityKernel.h) against InverseWarp::derivatives, its
// second method: random pairs of every type, both weightings, points far from and close to the
// elements, a scene far from the world's origin; and its builds against each other, bit for bit.
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

} // namespace

TEST(VelocityKernel, EqualsTheScalarDerivativesInSinglePrecision)
{
    // 1 to 20 pairs (one to three groups of 8 lanes), a cube of 100 voxels; half the points near an
    // element's origin (within a few voxels: near pairs dominate, some go to the double path).
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const Vec3d& shift : {Vec3d(0.0), Vec3d(4e4, -3e4, 2e4)}) {
        double worst = 0.0;
        for (int index = 0; index < 60; ++index) {
            const Trial c = trial(random, index, 100.0, shift);
            const double t = 0.05 + 0.9 * u(random);
            const InverseWarp warp(c.pairs, c.spec, t);
            const detail::VelocityKernel kernel(warp, 1.0);
            for (int k = 0; k < 40; ++k) {
                Vec3d p = shift + Vec3d(u(random), u(random), u(random)) * 120.0 - Vec3d(10.0);
                if (k % 2)
                    p = warp.interpolated(random() % warp.pairCount()).origin +
                        (Vec3d(u(random), u(random), u(random)) - Vec3d(0.5)) * 6.0;
                InverseWarp::Derivatives s, g, ks, kg;
                warp.derivatives(p, s, g);
                kernel.derivatives(p, ks, kg);
                worst = std::max({worst, relativeError(ks, s), relativeError(kg, g)});
            }
        }
        // Single precision: about 1e-7 relative per operation, the quotient rule's subtractions
        // of displacements; 1e-4 is a hundredth of the velocity's own 1% bound.
        EXPECT_LT(worst, 1e-4) << "shifted by " << shift;
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
    InverseWarp::Derivatives s, g, ks, kg;
    warp.derivatives(p, s, g);
    kernel.derivatives(p, ks, kg);
    EXPECT_EQ(std::memcmp(&s, &ks, sizeof s), 0);
    EXPECT_EQ(std::memcmp(&g, &kg, sizeof g), 0);
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
            for (int k = 0; k < 50; ++k) {
                const Vec3d p = Vec3d(u(random), u(random), u(random)) * 120.0 - Vec3d(10.0);
                InverseWarp::Derivatives a[2], b[2];
                baseline.derivatives(p, a[0], a[1]);
                vector.derivatives(p, b[0], b[1]);
                EXPECT_EQ(std::memcmp(a, b, sizeof a), 0) << "build " << int(build) << " at " << p;
            }
        }
    }
}
