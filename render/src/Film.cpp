#include "Film.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::render {

Film::Film(int width, int height, bool layers)
    : mWidth(width), mHeight(height), mRgba(size_t(width) * size_t(height) * 4, 0.0),
      mPassRgb(size_t(width) * size_t(height) * 3, 0.0), mCount(size_t(width) * size_t(height), 0u),
      mPassCount(mCount.size(), 0u), mTarget(mCount.size(), 0u)
{
    mDepth.assign(mCount.size(), layer::kNoDepth);
    if (layers) mLayers.assign(mCount.size() * layer::kFloats, 0.0); // the depth: mDepth
}

void Film::finishPass(size_t p, uint32_t added, const double passRgb[3])
{
    mCount[p] += added;
    mPassCount[p] = added;
    for (int c = 0; c < 3; ++c) mPassRgb[3 * p + c] = passRgb[c];
}

void Film::halves(size_t p, double a[3], double b[3], double& nA, double& nB) const
{
    nB = mPassCount[p];
    nA = double(mCount[p]) - nB;
    for (int c = 0; c < 3; ++c) {
        const double passSum = mPassRgb[3 * p + c];
        a[c] = nA > 0.0 ? (mRgba[4 * p + c] - passSum) / nA : 0.0;
        b[c] = nB > 0.0 ? passSum / nB : 0.0;
    }
}

double Film::variance(size_t p) const
{
    const double n = mCount[p], nB = mPassCount[p], nA = n - nB;
    if (nA <= 0.0 || nB <= 0.0) return 0.0;
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double b = mPassRgb[3 * p + c], a = mRgba[4 * p + c] - b;
        const double d = a / nA - b / nB;
        sum += d * d;
    }
    // var(A/nA - B/nB) = s^2 (1/nA + 1/nB) and var(mean) = s^2 / n for independent halves.
    return sum / 3.0 * (nA * nB) / (n * n);
}

namespace {

/// Over the pixels the frame covers: the sum of their variances, of their mean RGB, and how many.
struct Coverage {
    double error = 0.0, mean = 0.0;
    size_t pixels = 0;
    bool estimated = false;

    void add(double alpha, double meanRgb, double variance)
    {
        if (!(alpha > kNoiseMinAlpha)) return;
        ++pixels;
        error += variance;
        mean += meanRgb;
        estimated = estimated || variance > 0.0;
    }
    double noise() const
    {
        if (pixels == 0 || !estimated || !(mean > 0.0))
            return std::numeric_limits<double>::quiet_NaN();
        return std::sqrt(error / double(pixels)) / (mean / double(pixels));
    }
};

Coverage coverage(const Film& film, const std::vector<double>& rgba)
{
    Coverage c;
    for (size_t p = 0; p < film.pixels(); ++p) {
        const double n = std::max(1u, film.count(p));
        const double* px = &rgba[4 * p];
        c.add(px[3] / n, (px[0] + px[1] + px[2]) / (3.0 * n), film.variance(p));
    }
    return c;
}

} // namespace

double Film::noise() const
{
    return coverage(*this, mRgba).noise();
}

double Film::coveredMean() const
{
    const Coverage c = coverage(*this, mRgba);
    return c.pixels ? c.mean / double(c.pixels) : 0.0;
}

Image Film::resolve() const
{
    Image image;
    image.width = mWidth;
    image.height = mHeight;
    image.pixels.resize(mRgba.size());
    image.variance.resize(mCount.size());
    if (!mLayers.empty()) image.layers.resize(mLayers.size());
    for (size_t p = 0; p < mCount.size(); ++p) {
        const double n = std::max(1u, mCount[p]);
        for (int c = 0; c < 4; ++c) image.pixels[4 * p + c] = float(mRgba[4 * p + c] / n);
        image.variance[p] = float(variance(p));
        if (mLayers.empty()) continue;
        for (int c = 0; c < layer::kFloats; ++c) {
            image.layers[p * layer::kFloats + c] =
                c == layer::kDepth ? mDepth[p] : float(mLayers[p * layer::kFloats + c] / n);
        }
    }
    image.noise = estimateNoise(image);
    double samples = 0.0;
    for (uint32_t n : mCount) samples += n;
    image.meanSamples = mCount.empty() ? 0.0 : samples / double(mCount.size());
    return image;
}

double estimateNoise(const Image& image)
{
    if (image.variance.empty()) return std::numeric_limits<double>::quiet_NaN();
    Coverage c;
    for (size_t p = 0; p < image.variance.size(); ++p) {
        const float* px = &image.pixels[4 * p];
        c.add(px[3], (double(px[0]) + px[1] + px[2]) / 3.0, image.variance[p]);
    }
    return c.noise();
}

std::vector<double> boxMean3(const std::vector<double>& values, int width, int height)
{
    std::vector<double> out(values.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            double sum = 0.0;
            int n = 0;
            for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
                for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx, ++n)
                    sum += values[size_t(yy) * size_t(width) + size_t(xx)];
            out[size_t(y) * size_t(width) + size_t(x)] = sum / n;
        }
    return out;
}

std::vector<double> smoothedVariance(const Film& film)
{
    std::vector<double> perSample(film.pixels());
    for (size_t p = 0; p < perSample.size(); ++p) perSample[p] = film.variance(p) * film.count(p);
    std::vector<double> out = boxMean3(perSample, film.width(), film.height());
    for (size_t p = 0; p < out.size(); ++p) out[p] /= std::max(1u, film.count(p));
    return out;
}

} // namespace volmorph::render
