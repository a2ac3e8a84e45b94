// The approximated warp (warp/AdaptiveWarp.h) against the exact warp: its error bound, its kernel
// builds, its pair evaluations.
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;

TEST(AdaptiveWarp, WithinToleranceOfTheExactWarpOnRandomConfigurations)
{
    // Inverse-square weights at t = 1/4 and 3/4, Beier-Neely's at t = 1/2. The bound behind the
    // approximation is a worst case, so the error is checked at every voxel, not sampled.
    std::mt19937 random(2024);
    for (int n : {1, 2, 4, 8, 16, 32, 64}) {
        for (int trial = 0; trial < 3; ++trial) {
            const auto pairs = randomPairs(random, n, 96.0);
            WarpSpec spec;
            spec.epsilon = 2.0; // index units here (unit = 1)
            if (trial == 2) {
                spec.weighting = Weighting::BeierNeely;
                spec.a = 2.0;
                spec.b = 2.0;
                spec.p = 0.5;
            }
            const double t = 0.25 + 0.25 * trial;
            const InverseWarp warp(pairs, spec, t);
            const double tolerance = 0.25;
            const detail::AdaptiveWarp adaptive(warp, tolerance);
            detail::AdaptiveWarpStats stats;
            // Every voxel up to 16 pairs; every 3rd beyond keeps the test quick.
            const double worst = largestError(warp, adaptive, 95, n <= 16 ? 1 : 3, stats);
            EXPECT_LE(worst, tolerance) << n << " pairs, trial " << trial;
            EXPECT_LE(stats.maxErrorVoxels, tolerance);
            EXPECT_EQ(stats.leaves, 12u * 12u * 12u);
            // Pairs packed this densely (2 voxels of epsilon, elements 2-26 voxels, moved up to
            // 24) leave most pairs near most voxels; the next test is the efficient case.
            const double pairEvaluations =
                double(stats.exactEvaluations) * n + double(stats.nearEvaluations);
            EXPECT_LE(pairEvaluations, 1.01 * 96.0 * 96 * 96 * n);
        }
    }
}

TEST(AdaptiveWarp, ErrorBoundHoldsAtEveryVoxelOfEveryLeaf)
{
    // Each leaf's a-priori bound against the exact warp at its voxels, from tolerances that make
    // most pairs near down to none but the kinks (a huge tolerance), for both weight laws: the
    // bound must hold leaf by leaf, not only below the tolerance. Single-precision points allow
    // 1e-3 voxel of rounding beyond it.
    std::mt19937 random(1999);
    double tightest = 0.0; // the largest error / bound seen (how tight the bound is)
    size_t checked = 0;
    for (int n : {1, 2, 4, 8, 16, 32, 64}) {
        for (int trial = 0; trial < 2; ++trial) {
            const auto pairs = randomPairs(random, n, 64.0);
            WarpSpec spec;
            spec.epsilon = trial == 0 ? 1.0 : 4.0;
            if (trial == 1) {
                spec.weighting = Weighting::BeierNeely;
                spec.a = 3.0;
                spec.b = 1.5;
                spec.p = 0.5;
            }
            const InverseWarp warp(pairs, spec, 0.4 + 0.2 * trial);
            for (double tolerance : {0.05, 0.5, 4.0, 1e6}) {
                const detail::AdaptiveWarp adaptive(warp, tolerance);
                std::mutex m;
                adaptive.forEachLeaf(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(63)),
                                     nullptr, nullptr, [&](const detail::WarpLeaf& leaf) {
                                         const double local =
                                             leafError(warp, leaf, n <= 16 ? 1 : 3);
                                         std::lock_guard<std::mutex> lock(m);
                                         ++checked;
                                         EXPECT_LE(local, leaf.errorBound + 1e-3)
                                             << n << " pairs, trial " << trial << ", tolerance "
                                             << tolerance << ", leaf " << leaf.origin;
                                         if (leaf.errorBound > 1e-3)
                                             tightest = std::max(tightest, local / leaf.errorBound);
                                     });
            }
        }
    }
    EXPECT_EQ(checked, 7u * 2u * 4u * 512u);
    std::printf("largest error / bound over the leaves: %.3f\n", tightest);
}

TEST(AdaptiveWarp, VectorAndBaselineKernelsGiveTheSameBits)
{
    // The leaf kernel, the bound and the lattice's sums run in AVX2 (or AVX2 with AVX-512VL) where
    // the CPU has it, each build compared with the baseline here; a farm
    // mixing machines must still get the same frames. Every pair type, near and far pairs, both
    // weight laws, with and without the domain test (trial 2: occupancies of a sphere on both
    // sides, so that cells, leaves and the filled points' boxes are culled), compared bit for bit.
    if (detail::bestKernelBuild() == detail::KernelBuild::Baseline)
        GTEST_SKIP() << "no vector build of the leaf kernel here (they are built by GCC for x86-64 "
                        "only, and run "
                        "where the CPU has AVX2): nothing to compare with the baseline";
    std::mt19937 random(7);
    const auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        30.0f, openvdb::Vec3f(40.0f, 50.0f, 45.0f), 1.0f);
    const detail::Occupancy occupancy(sphere->tree());
    for (int trial = 0; trial < 3; ++trial) {
        const auto pairs = randomPairs(random, 12, 96.0);
        WarpSpec spec;
        spec.epsilon = 2.0;
        if (trial == 1) {
            spec.weighting = Weighting::BeierNeely;
            spec.a = 2.0;
            spec.b = 2.0;
            spec.p = 0.5;
        }
        const InverseWarp warp(pairs, spec, 0.4);
        // 0.25: most leaves have near pairs; 1e6: only the kinks are near, and the other leaves
        // take the kernel's path with no near pair.
        for (const double tolerance : {0.25, 1e6}) {
            auto run = [&](detail::KernelBuild build) {
                const detail::AdaptiveWarp adaptive(warp, tolerance, build);
                EXPECT_EQ(adaptive.kernelBuild(), build);
                std::mutex m;
                std::map<std::tuple<int, int, int>, std::vector<float>> leaves;
                detail::AdaptiveWarpStats stats;
                const detail::Occupancy* occ = trial == 2 ? &occupancy : nullptr;
                adaptive.forEachLeaf(
                    openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(95)), occ, occ,
                    [&](const detail::WarpLeaf& leaf) {
                        std::vector<float> v(&leaf.s[0][0], &leaf.s[0][0] + 3 * 512);
                        v.insert(v.end(), &leaf.t[0][0], &leaf.t[0][0] + 3 * 512);
                        std::lock_guard<std::mutex> lock(m);
                        leaves[{leaf.origin.x(), leaf.origin.y(), leaf.origin.z()}] = std::move(v);
                    },
                    &stats);
                EXPECT_GT(stats.nearEvaluations, 0u); // the near-pair loops ran
                if (tolerance > 1.0) {
                    EXPECT_GT(stats.allFarLeaves, 0u); // and the path without them
                }
                return leaves;
            };
            const auto baseline = run(detail::KernelBuild::Baseline);
            if (trial < 2) {
                ASSERT_EQ(baseline.size(), 12u * 12u * 12u);
            } else {
                ASSERT_GT(baseline.size(), 0u);
                ASSERT_LT(baseline.size(), 12u * 12u * 12u); // the domain test culled leaves
            }
            // Each vector build this CPU has (the baseline alone where it has none).
            for (const detail::KernelBuild build :
                 {detail::KernelBuild::Avx2, detail::KernelBuild::Avx512}) {
                if (int(detail::bestKernelBuild()) < int(build)) continue; // not on this CPU
                const auto vector = run(build);
                ASSERT_EQ(vector.size(), baseline.size());
                size_t differing = 0;
                for (const auto& [origin, v] : vector)
                    differing += std::memcmp(v.data(), baseline.at(origin).data(),
                                             v.size() * sizeof(float)) != 0;
                EXPECT_EQ(differing, 0u)
                    << "build " << int(build) << ", trial " << trial << ", tolerance " << tolerance;
            }
        }
    }
}

TEST(AdaptiveWarp, FewPairEvaluationsWherePairsAreApart)
{
    // Eight pairs of each type at the corners of a 2^3 grid 96 voxels apart, moved by up to 8
    // voxels and turned by up to 20 degrees, epsilon 4 voxels: most of the 192^3 box is far
    // from all of them, and most of the exact warp's pair evaluations are saved (0.22 of them are
    // made; the bound is a worst case, some 10 times the error actually made).
    std::mt19937 random(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<FeaturePairSpec> pairs;
    for (int k = 0; k < 8; ++k) {
        const Vec3d at(48.0 + 96 * (k & 1), 48.0 + 96 * ((k >> 1) & 1), 48.0 + 96 * ((k >> 2) & 1));
        const Vec3d axis = Vec3d(u(random), u(random), u(random) + 2.0).unit();
        const double angle = u(random) * M_PI / 9.0;
        pairs.push_back(pair(FeatureType(k % 4),
                             element(at, Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(12, 8, 6)),
                             element(at + 8.0 * Vec3d(u(random), u(random), u(random)),
                                     rotate(Vec3d(1, 0, 0), axis, angle),
                                     rotate(Vec3d(0, 1, 0), axis, angle), Vec3d(14, 7, 6))));
    }
    WarpSpec spec;
    spec.epsilon = 4.0;
    const InverseWarp warp(pairs, spec, 0.5);
    const detail::AdaptiveWarp adaptive(warp, 0.25);
    detail::AdaptiveWarpStats stats;
    const double worst = largestError(warp, adaptive, 191, 1, stats);
    const double voxels = 192.0 * 192 * 192;
    const double share =
        (double(stats.exactEvaluations) * 8 + double(stats.nearEvaluations)) / (8 * voxels);
    std::cout << "largest error " << worst << " voxel, bound " << stats.maxErrorVoxels
              << ", pair evaluations " << share << " of the exact warp's\n";
    EXPECT_LE(worst, 0.25);
    EXPECT_LE(stats.maxErrorVoxels, 0.25);
    EXPECT_LT(share, 0.3);
}
