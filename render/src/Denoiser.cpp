#include "Denoiser.h"

#include <volmorph/core/Interrupter.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::render {
namespace {

constexpr int kRadius = 7; ///< the search window: (2 kRadius + 1)^2 neighbours
constexpr int kPatch = 3;  ///< the patches compared: (2 kPatch + 1)^2 pixels
constexpr double kK2 =
    0.45 * 0.45; ///< Rousselle et al.'s k^2: how many variances a patch may differ by
constexpr double kAlphaSigma = 0.05; ///< alpha differences above this separate pixels
constexpr double kDepthSigma = 0.03; ///< relative depth differences above this separate pixels

/// The layers filtered with the colour: the radiance ones.
constexpr int kFilteredLayers[] = {layer::kVolume,   layer::kVolume + 1,   layer::kVolume + 2,
                                   layer::kDirect,   layer::kDirect + 1,   layer::kDirect + 2,
                                   layer::kIndirect, layer::kIndirect + 1, layer::kIndirect + 2,
                                   layer::kEmission, layer::kEmission + 1, layer::kEmission + 2};

/// What the weights are computed from, per pixel.
struct Guide {
    int width = 0, height = 0;
    std::vector<float> rgb, variance, alpha, depth;
    /// The two halves' difference, scaled so that its square estimates the pixel's variance.
    std::vector<float> difference;
};

Guide makeGuide(const Film& film, const std::vector<float>& depth, const Image& image)
{
    Guide g;
    g.width = film.width();
    g.height = film.height();
    const size_t n = film.pixels();
    g.rgb.resize(3 * n);
    g.alpha.resize(n);
    g.difference.resize(3 * n);
    g.depth = depth;
    const std::vector<double> smooth = smoothedVariance(film);
    g.variance.assign(smooth.begin(), smooth.end());
    for (size_t p = 0; p < n; ++p) {
        for (int c = 0; c < 3; ++c) g.rgb[3 * p + c] = image.pixels[4 * p + c];
        g.alpha[p] = image.pixels[4 * p + 3];
        double a[3], b[3], nA, nB;
        film.halves(p, a, b, nA, nB);
        const double scale = nA > 0.0 && nB > 0.0 ? std::sqrt(nA * nB) / (nA + nB) : 0.0;
        for (int c = 0; c < 3; ++c) g.difference[3 * p + c] = float((a[c] - b[c]) * scale);
    }
    return g;
}

/// The feature weight of neighbour q for pixel p: alike in alpha and in depth.
double featureWeight(const Guide& g, size_t p, size_t q)
{
    const double da = (g.alpha[p] - g.alpha[q]) / kAlphaSigma;
    double w = std::exp(-0.5 * da * da);
    const float zp = g.depth[p], zq = g.depth[q];
    const bool hp = zp < layer::kNoDepth, hq = zq < layer::kNoDepth;
    if (hp != hq) return 0.0;
    if (hp) {
        const double dz = (zp - zq) / (kDepthSigma * std::max(1e-6f, std::min(zp, zq)));
        w *= std::exp(-0.5 * dz * dz);
    }
    return w;
}

/// For one offset (dx, dy): each pixel's colour distance to its neighbour at the offset, per
/// Rousselle et al.: ((u_p - u_q)^2 - (v_p + min(v_p, v_q))) / (eps + k^2 (v_p + v_q)), averaged
/// over the channels; +inf where the neighbour is outside the image.
void pixelDistances(const Guide& g, int dx, int dy, std::vector<float>& out)
{
    tbb::parallel_for(
        tbb::blocked_range<int>(0, g.height, 8), [&](const tbb::blocked_range<int>& r) {
            for (int y = r.begin(); y != r.end(); ++y)
                for (int x = 0; x < g.width; ++x) {
                    const size_t p = size_t(y) * size_t(g.width) + size_t(x);
                    const int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= g.width || qy >= g.height) {
                        out[p] = std::numeric_limits<float>::infinity();
                        continue;
                    }
                    const size_t q = size_t(qy) * size_t(g.width) + size_t(qx);
                    const double vp = g.variance[p], vq = g.variance[q];
                    double sum = 0.0;
                    for (int c = 0; c < 3; ++c) {
                        const double d = double(g.rgb[3 * p + c]) - g.rgb[3 * q + c];
                        sum += d * d;
                    }
                    out[p] =
                        float((sum / 3.0 - (vp + std::min(vp, vq))) / (1e-10 + kK2 * (vp + vq)));
                }
        });
}

/// The mean of `d` over each pixel's patch (clamped at the borders): a separable box filter.
void patchMean(int width, int height, std::vector<float>& d, std::vector<float>& scratch)
{
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y)
            for (int x = 0; x < width; ++x) {
                double sum = 0.0;
                const int x0 = std::max(0, x - kPatch), x1 = std::min(width - 1, x + kPatch);
                for (int xx = x0; xx <= x1; ++xx) sum += d[size_t(y) * size_t(width) + size_t(xx)];
                scratch[size_t(y) * size_t(width) + size_t(x)] = float(sum / (x1 - x0 + 1));
            }
    });
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
            const int y0 = std::max(0, y - kPatch), y1 = std::min(height - 1, y + kPatch);
            for (int x = 0; x < width; ++x) {
                double sum = 0.0;
                for (int yy = y0; yy <= y1; ++yy)
                    sum += scratch[size_t(yy) * size_t(width) + size_t(x)];
                d[size_t(y) * size_t(width) + size_t(x)] = float(sum / (y1 - y0 + 1));
            }
        }
    });
}

} // namespace

DenoiseEstimate denoise(const Film& film, const std::vector<float>& depth, Image& image,
                        openvdb::util::NullInterrupter* interrupter)
{
    const Guide g = makeGuide(film, depth, image);
    const int w = g.width, h = g.height;
    const size_t n = film.pixels();
    const bool layers = !image.layers.empty();
    const int channels = 3 + 3 + (layers ? int(std::size(kFilteredLayers)) : 0);
    // Per pixel: the weights' sum and, per channel, the weighted sum (RGB, the difference, layers).
    std::vector<double> weights(n, 0.0), sums(n * size_t(channels), 0.0);
    std::vector<float> d(n), scratch(n);
    for (int dy = -kRadius; dy <= kRadius; ++dy)
        for (int dx = -kRadius; dx <= kRadius; ++dx) {
            if (interrupter && interrupter->wasInterrupted()) throw Interrupted();
            pixelDistances(g, dx, dy, d);
            patchMean(w, h, d, scratch);
            tbb::parallel_for(
                tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& r) {
                    for (int y = r.begin(); y != r.end(); ++y)
                        for (int x = 0; x < w; ++x) {
                            const int qx = x + dx, qy = y + dy;
                            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
                            const size_t p = size_t(y) * size_t(w) + size_t(x),
                                         q = size_t(qy) * size_t(w) + size_t(qx);
                            const double weight =
                                std::exp(-std::max(0.0, double(d[p]))) * featureWeight(g, p, q);
                            if (!(weight > 0.0)) continue;
                            weights[p] += weight;
                            double* s = &sums[p * size_t(channels)];
                            for (int c = 0; c < 3; ++c) s[c] += weight * image.pixels[4 * q + c];
                            for (int c = 0; c < 3; ++c)
                                s[3 + c] += weight * g.difference[3 * q + c];
                            if (!layers) continue;
                            const float* l = &image.layers[q * layer::kFloats];
                            for (size_t k = 0; k < std::size(kFilteredLayers); ++k)
                                s[6 + k] += weight * l[kFilteredLayers[k]];
                        }
                });
        }
    DenoiseEstimate estimate;
    estimate.variance.resize(n);
    for (size_t p = 0; p < n; ++p) {
        const double* s = &sums[p * size_t(channels)];
        const double total = weights[p]; // at least the pixel's own weight, 1
        double e = 0.0;
        for (int c = 0; c < 3; ++c) {
            image.pixels[4 * p + c] = float(s[c] / total);
            e += (s[3 + c] / total) * (s[3 + c] / total);
        }
        estimate.variance[p] = e / 3.0;
        image.variance[p] = float(e / 3.0);
        if (!layers) continue;
        float* l = &image.layers[p * layer::kFloats];
        for (size_t k = 0; k < std::size(kFilteredLayers); ++k)
            l[kFilteredLayers[k]] = float(s[6 + k] / total);
    }
    image.noise = estimateNoise(image);
    estimate.noise = image.noise;
    return estimate;
}

} // namespace volmorph::render
