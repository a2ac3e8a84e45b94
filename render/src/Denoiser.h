// A denoiser for the frames of a noise target: non-local means on the colour with the distance of
// Rousselle, Knaus and Zwicker 2012 ("Adaptive rendering with non-local means filtering"): two
// pixels' patches compared in units of their estimated variance, so that the filter averages what
// differs by noise only and keeps what differs by more; guided by what the renderer knows without
// noise (the alpha and the depth where the alpha passes one half), which keeps edges between the
// body and the floor or the sky. Each filter weight is computed once per pixel pair and applied to
// RGB and to every radiance layer alike (a linear filter: direct + indirect + emission = RGB still
// holds), never to alpha, shadow or depth.
//
// The filtered frame's noise is estimated from the two halves of each pixel's samples filtered
// with the same weights: their difference, scaled to the whole pixel's variance, filtered, is an
// estimate of the filtered pixel's error whose square has the filtered pixel's variance as its
// expectation (for weights independent of the halves' difference). The filter's bias (what it
// blurs) is not in it; BENCHMARKS.md measures it against converged references.
#pragma once

#include "Film.h"

#include <volmorph/render/Renderer.h>

#include <openvdb/util/NullInterrupter.h>

#include <vector>

namespace volmorph::render {

/// The filtered image's per-pixel error estimates (squared, like Image::variance) and its noise as
/// estimateNoise takes it.
struct DenoiseEstimate {
    std::vector<double> variance;
    double noise = 0.0;
};

/// Filters `image` (resolved from `film`) in place: RGB and the radiance layers (volume RGB,
/// direct, indirect, emission); sets image.variance and image.noise to the filtered image's.
/// `depth` is each pixel's nearest depth (kNoDepth: none). Deterministic for any thread count.
/// Throws Interrupted when `interrupter` asks (between the window's offsets).
DenoiseEstimate denoise(const Film& film, const std::vector<float>& depth, Image& image,
                        openvdb::util::NullInterrupter* interrupter);

} // namespace volmorph::render
