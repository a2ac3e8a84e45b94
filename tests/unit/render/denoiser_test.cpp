// The denoiser (render/src/Denoiser.h) on a film of known truth: samples with Gaussian noise around
// a picture of two flat colours and an alpha edge, so that its error, its bias at the edges and
// its own estimate can be checked against what is known exactly.
#include "Denoiser.h"
#include "Film.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <random>

using namespace volmorph::render;

namespace {

constexpr int kWidth = 64, kHeight = 48;

/// The truth: a colour edge at x = 32 (0.2 left, 0.6 right) inside the body (alpha 1), and the
/// background (alpha 0, black) below y = 8.
double truth(int x, int y, int c)
{
    if (y < 8) return 0.0;
    return (x < 32 ? 0.2 : 0.6) * (1.0 + 0.1 * c);
}

/// A film of `samples` samples per pixel, in two passes (halves), each sample the truth plus
/// Gaussian noise of standard deviation sigma.
Film noisyFilm(int samples, double sigma, unsigned seed)
{
    Film film(kWidth, kHeight, false);
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    for (int half = 0; half < 2; ++half)
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) {
                const size_t p = size_t(y) * kWidth + size_t(x);
                double pass[3] = {0, 0, 0};
                for (int s = 0; s < samples / 2; ++s)
                    for (int c = 0; c < 3; ++c) {
                        const double v = truth(x, y, c) + (y < 8 ? 0.0 : noise(random));
                        film.rgba(p)[c] += v;
                        pass[c] += v;
                    }
                film.rgba(p)[3] += y < 8 ? 0.0 : samples / 2;
                if (y >= 8) film.depth(p) = 2.0f;
                film.finishPass(p, uint32_t(samples / 2), pass);
            }
    return film;
}

/// The relative RMSE of `image` against the truth over the body, and the larger relative bias of
/// the two columns either side of the colour edge (their mean error over the column's truth).
void errors(const Image& image, double& rmse, double& edge)
{
    double square = 0.0, mean = 0.0;
    int n = 0;
    double column[2] = {0.0, 0.0};
    for (int y = 8; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x)
            for (int c = 0; c < 3; ++c) {
                const double e = image.at(x, y)[c] - truth(x, y, c);
                square += e * e;
                mean += truth(x, y, c);
                ++n;
                if (x == 31 || x == 32) column[x - 31] += e / truth(x, y, c);
            }
    rmse = std::sqrt(square / n) / (mean / n);
    const double rows = 3.0 * (kHeight - 8);
    edge = std::max(std::abs(column[0]) / rows, std::abs(column[1]) / rows);
}

} // namespace

TEST(Denoiser, LowersTheErrorKeepsTheEdgeAndEstimatesWhatRemains)
{
    const double sigma = 0.5;
    Film film = noisyFilm(16, sigma, 1);
    Image raw = film.resolve();
    double rawRmse, rawEdge;
    errors(raw, rawRmse, rawEdge);
    Image image = film.resolve();
    const DenoiseEstimate estimate = denoise(film, film.depths(), image, nullptr);
    double rmse, edge;
    errors(image, rmse, edge);
    std::printf("raw: rmse %.4f (estimate %.4f); denoised: rmse %.4f (estimate %.4f), bias at the "
                "edge %.3f (raw %.3f)\n",
                rawRmse, raw.noise, rmse, estimate.noise, edge, rawEdge);
    EXPECT_LT(rmse, rawRmse / 3.0); // at least 9x the samples' worth
    // The edge between 0.2 and 0.6 is not smeared: the columns either side keep their colour
    // within 10% on average (smearing them half-way would be 100% and 33%).
    EXPECT_LT(edge, 0.1);
    // The estimate of what remains is honest to a factor 1.5 here, where the filter has no bias
    // to hide but at the edge.
    EXPECT_GT(estimate.noise, rmse / 1.5);
    EXPECT_LT(estimate.noise, rmse * 1.5);
    // The background (alpha 0) is left black: no colour bleeds across the alpha edge.
    for (int x = 0; x < kWidth; ++x) EXPECT_EQ(image.at(x, 7)[0], 0.0f);
}

TEST(Denoiser, ADenoisedFrameIsTheSameAtAnyThreadCount)
{
    // The filter's sums run in a fixed order per pixel; TBB's partition decides nothing.
    Film film = noisyFilm(8, 0.5, 2);
    Image a = film.resolve(), b = film.resolve();
    denoise(film, film.depths(), a, nullptr);
    tbb::task_arena(1).execute([&] { denoise(film, film.depths(), b, nullptr); });
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(a.variance, b.variance);
}
