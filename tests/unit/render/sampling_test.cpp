// The renderer's low-discrepancy numbers (render/src/Sobol.h, Sampling.h): nets as Sobol's
// construction promises them, kept by the scrambles, and uniform over seeds.
#include "Sampling.h"
#include "Sobol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

using namespace volmorph::render;

namespace {

/// True when the first 2^m values fall one in each interval [k 2^-m, (k + 1) 2^-m).
bool stratified1D(const std::vector<double>& u, int m)
{
    std::vector<int> hits(size_t(1) << m, 0);
    for (size_t i = 0; i < (size_t(1) << m); ++i) ++hits[size_t(u[i] * double(hits.size()))];
    for (int h : hits)
        if (h != 1) return false;
    return true;
}

/// True when the first 2^m points (x, y) fall one in each elementary interval of area 2^-m: every
/// box 2^-a by 2^-(m - a), a from 0 to m (a (0, m, 2)-net).
bool net2D(const std::vector<double>& x, const std::vector<double>& y, int m)
{
    const size_t n = size_t(1) << m;
    for (int a = 0; a <= m; ++a) {
        const size_t nx = size_t(1) << a, ny = size_t(1) << (m - a);
        std::vector<int> hits(n, 0);
        for (size_t i = 0; i < n; ++i)
            ++hits[size_t(x[i] * double(nx)) * ny + size_t(y[i] * double(ny))];
        for (int h : hits)
            if (h != 1) return false;
    }
    return true;
}

std::vector<double> dimension(uint32_t dim, uint64_t seed, size_t n)
{
    std::vector<double> u(n);
    for (size_t i = 0; i < n; ++i) u[i] = sobol::sample(uint32_t(i), dim, seed);
    return u;
}

} // namespace

TEST(Sobol, UnscrambledPointsAreNets)
{
    // Sobol's construction: each dimension's first 2^m points stratify [0, 1) by 2^-m, and the
    // first two dimensions together are a (0, m, 2)-net.
    const size_t n = 1u << 10;
    std::vector<std::vector<double>> u(4, std::vector<double>(n));
    for (int d = 0; d < 4; ++d)
        for (size_t i = 0; i < n; ++i)
            u[d][i] = double(sobol::point(uint32_t(i), d)) / 4294967296.0;
    for (int m = 1; m <= 10; ++m) {
        for (int d = 0; d < 4; ++d) EXPECT_TRUE(stratified1D(u[d], m)) << "dim " << d << " m " << m;
        EXPECT_TRUE(net2D(u[0], u[1], m)) << "m " << m;
    }
    // Dimension 1 (Joe and Kuo's first polynomial, x + 1) in index order (not Gray code's): 0, 1/2,
    // 3/4, 1/4, 5/8, 1/8.
    const double known[6] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125};
    for (int i = 0; i < 6; ++i) EXPECT_EQ(u[1][size_t(i)], known[i]) << i;
}

TEST(Sobol, ScrambledAndShuffledPointsStayNetsForEverySeed)
{
    // Owen scrambling keeps every elementary interval's count, and the index shuffle maps the first
    // 2^m indices onto an aligned block of 2^m: a pixel's first 2^m samples are a net whatever its
    // seed, in every group of four dimensions.
    for (uint64_t seed : {1ull, 77ull, 0xdeadbeefull}) {
        for (uint32_t group : {0u, 3u, 7u}) {
            const auto x = dimension(4 * group, seed, 256), y = dimension(4 * group + 1, seed, 256);
            const auto z = dimension(4 * group + 2, seed, 256);
            for (int m = 1; m <= 8; ++m) {
                EXPECT_TRUE(net2D(x, y, m)) << seed << " group " << group << " m " << m;
                EXPECT_TRUE(stratified1D(z, m)) << seed << " group " << group << " m " << m;
            }
        }
    }
}

TEST(Sobol, EachSampleIsUniformOverSeeds)
{
    // Over pixels (seeds), one sample's value in one dimension is uniform on [0, 1): mean 1/2 and
    // variance 1/12 (standard errors 0.0009 and 0.0003 over 100,000 seeds), and its quarters
    // equally likely. An estimator using it is unbiased.
    for (uint32_t dim : {0u, 1u, 6u, 29u}) {
        const uint32_t index = 5;
        const int seeds = 100000;
        double sum = 0.0, sum2 = 0.0;
        int quarters[4] = {0, 0, 0, 0};
        for (int s = 0; s < seeds; ++s) {
            const double u = sobol::sample(index, dim, uint64_t(s) * 7919u + 1u);
            ASSERT_GE(u, 0.0);
            ASSERT_LT(u, 1.0);
            sum += u;
            sum2 += u * u;
            ++quarters[int(u * 4.0)];
        }
        const double mean = sum / seeds, variance = sum2 / seeds - mean * mean;
        EXPECT_NEAR(mean, 0.5, 0.005) << dim;
        EXPECT_NEAR(variance, 1.0 / 12.0, 0.002) << dim;
        for (int q : quarters) EXPECT_NEAR(q, seeds / 4, seeds / 50) << dim;
    }
}

TEST(Sobol, RandomTakesPairsFromOneGroupAndFallsBackAfterItsDimensions)
{
    // nextLD2 after an odd number of dimensions skips one, so that the pair is stratified together;
    // after kLowDiscrepancyDims, numbers come from the counter-based generator (still in [0, 1)).
    Random a(3, 9, 1);
    const double first = a.nextLD();
    EXPECT_EQ(first, sobol::sample(9, 0, a.sequence));
    double u1, u2;
    a.nextLD2(u1, u2);
    EXPECT_EQ(u1, sobol::sample(9, 2, a.sequence));
    EXPECT_EQ(u2, sobol::sample(9, 3, a.sequence));
    while (a.dim < Random::kLowDiscrepancyDims) a.nextLD();
    Random b = a;
    EXPECT_EQ(a.nextLD(), b.next());
}
