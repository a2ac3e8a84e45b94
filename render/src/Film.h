// The film an image's samples add up on, pass after pass, and what it says about its own noise.
//
// Each pixel keeps the running sums of its samples (RGBA and the layers, in the order the samples
// were drawn, so one pass of n samples and several passes adding up to n give the same bits) and,
// apart, the RGB sum of the samples of its last pass. Passes double a pixel's samples, so the two
// halves of them, A (before the last pass) and B (the last pass), are two independent estimates of
// the pixel (each a whole net of the pixel's Sobol sequence), and (A - B)^2 nA nB / n^2 estimates
// the variance of their mean without assuming the samples independent (Cycles' adaptive sampling
// reads the same two halves).
#pragma once

#include <volmorph/render/Renderer.h>

#include <cstdint>
#include <vector>

namespace volmorph::render {

class Film {
public:
    Film(int width, int height, bool layers);

    int width() const { return mWidth; }
    int height() const { return mHeight; }
    size_t pixels() const { return mCount.size(); }
    bool hasLayers() const { return !mLayers.empty(); }

    /// Pixel p's samples so far, and how many the next pass should reach (0: none to add).
    uint32_t count(size_t p) const { return mCount[p]; }
    uint32_t& target(size_t p) { return mTarget[p]; }
    uint32_t target(size_t p) const { return mTarget[p]; }

    /// Sums the samples from count(p) to target(p) - 1 add (RGBA, the layers) into pixel p: the
    /// renderer's samples call this once per pixel and pass, from one thread.
    double* rgba(size_t p) { return &mRgba[4 * p]; }
    double* layers(size_t p) { return mLayers.empty() ? nullptr : &mLayers[layer::kFloats * p]; }
    /// Marks pass `added` samples of pixel p done, `passRgb` their RGB sum.
    void finishPass(size_t p, uint32_t added, const double passRgb[3]);

    /// Pixel p's two halves: the mean RGB of its samples before the last pass (a, nA of them) and
    /// of the last pass's (b, nB).
    void halves(size_t p, double a[3], double b[3], double& nA, double& nB) const;

    /// Each pixel's nearest depth over its samples (as layer::kDepth; kept with or without the
    /// layers, for the denoiser).
    float& depth(size_t p) { return mDepth[p]; }
    const std::vector<float>& depths() const { return mDepth; }

    /// The estimated variance of pixel p's mean RGB (mean over the channels); 0 before it has two
    /// halves.
    double variance(size_t p) const;

    /// The frame's estimated relative noise as estimateNoise takes it, from the sums; and the mean
    /// RGB over the pixels it covers (0 when none).
    double noise() const;
    double coveredMean() const;

    /// The image: each pixel's mean (the depth layer its nearest), its variance, and the frame's
    /// estimated noise (estimateNoise).
    Image resolve() const;

private:
    int mWidth, mHeight;
    std::vector<double> mRgba, mLayers, mPassRgb;
    std::vector<float> mDepth;
    std::vector<uint32_t> mCount, mPassCount, mTarget;
};

/// The variance of each pixel's estimate box-filtered over its 3x3 neighbourhood, per sample
/// (times the pixel's count), and divided by its own count again: a steadier figure to decide by
/// than one pixel's two halves.
std::vector<double> smoothedVariance(const Film& film);

/// The mean of `values` (width x height, row-major) over each pixel's 3x3 neighbourhood.
std::vector<double> boxMean3(const std::vector<double>& values, int width, int height);

} // namespace volmorph::render
