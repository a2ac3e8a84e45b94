// The noise target (RenderSettings::noise, render/src/Film.h): the frame's estimated noise against
// the error measured between two seeds, adaptive sampling that stops at the target, and what must
// not change under it (the thread count's independence, the layers' sum, exact samples at 0).
#include <volmorph/render/Renderer.h>

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <cstdio>
#include <cstring>

using namespace volmorph;
using render::Camera;

namespace {

constexpr int kPixels = 48;

/// A fog ball of radius 0.5 lit by a sun and a constant sky, its multiple scattering path traced:
/// noisy where it is thin, smooth outside.
render::Image renderBall(double noise, int samples, unsigned seed, int threads = 0,
                         bool layers = false)
{
    static const auto sphere = [] {
        auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
            0.5f, openvdb::Vec3f(0.0f), 1.0f / 48.0f, 3.0f);
        return g;
    }();
    render::Medium medium;
    medium.kind = render::Medium::Kind::LevelSet;
    medium.extinction = 6.0;
    medium.albedo = 0.9;
    render::Light sun, sky;
    sun.direction = Vec3d(-1, -1, -0.5);
    sun.intensity = 3.0;
    sky.type = render::Light::Type::Environment;
    sky.intensity = 0.3;
    render::RenderSettings settings;
    settings.samples = samples;
    settings.noise = noise;
    settings.bounces = 4;
    settings.seed = seed;
    settings.threads = threads;
    settings.layers = layers;
    const Camera camera(Camera::Projection::Perspective, Vec3d(0, 0, 3), Vec3d(0, 0, 0),
                        Vec3d(0, 1, 0), 30.0, 0.0, kPixels, kPixels);
    return render::renderVolume(*sphere, nullptr, camera, {sun, sky}, medium, settings);
}

/// The relative RMSE of one of two independent renders against the converged image, from their
/// difference (its mean square is twice each one's), over the pixels both cover.
double measuredNoise(const render::Image& a, const render::Image& b)
{
    double square = 0.0, mean = 0.0;
    size_t n = 0;
    for (size_t p = 0; p < a.pixels.size() / 4; ++p) {
        const float* x = &a.pixels[4 * p];
        const float* y = &b.pixels[4 * p];
        if (!(x[3] > render::kNoiseMinAlpha && y[3] > render::kNoiseMinAlpha)) continue;
        for (int c = 0; c < 3; ++c) {
            square += (double(x[c]) - y[c]) * (double(x[c]) - y[c]);
            mean += 0.5 * (double(x[c]) + y[c]);
        }
        n += 3;
    }
    return std::sqrt(square / double(n) / 2.0) / (mean / double(n));
}

} // namespace

TEST(Noise, TheEstimateIsWithinAFactorOf1Point5OfTheMeasuredError)
{
    for (int samples : {16, 64}) {
        const render::Image a = renderBall(0.0, samples, 1), b = renderBall(0.0, samples, 2);
        const double measured = measuredNoise(a, b), estimated = 0.5 * (a.noise + b.noise);
        std::printf("%d samples: estimated noise %.4f (%.4f, %.4f), measured %.4f\n", samples,
                    estimated, a.noise, b.noise, measured);
        EXPECT_EQ(a.meanSamples, double(samples));
        EXPECT_GT(estimated, measured / 1.5) << samples;
        EXPECT_LT(estimated, measured * 1.5) << samples;
    }
}

TEST(Noise, AdaptiveSamplingStopsAtTheTargetWithAnHonestEstimate)
{
    const double target = 0.02;
    const render::Image a = renderBall(target, 4096, 1), b = renderBall(target, 4096, 2);
    const double measured = measuredNoise(a, b);
    std::printf("target %.3f: estimated %.4f and %.4f, measured %.4f, %.1f and %.1f samples per "
                "pixel\n",
                target, a.noise, b.noise, measured, a.meanSamples, b.meanSamples);
    EXPECT_LE(a.noise, target);
    EXPECT_LE(b.noise, target);
    EXPECT_LT(measured, target * 1.5);
    // It stopped at the target, not at the cap, and spent more than the first passes.
    EXPECT_LT(a.meanSamples, 4096.0);
    EXPECT_GT(a.meanSamples, 16.0);
}

TEST(Noise, AdaptiveFramesDoNotDependOnTheThreadCount)
{
    const render::Image one = renderBall(0.03, 1024, 5, 1, true),
                        two = renderBall(0.03, 1024, 5, 2, true);
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    EXPECT_EQ(0,
              std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)));
    EXPECT_EQ(0,
              std::memcmp(one.layers.data(), two.layers.data(), one.layers.size() * sizeof(float)));
    EXPECT_EQ(one.noise, two.noise);
}

TEST(Noise, UnderAdaptiveSamplingTheLayersStillAddUpToTheBeauty)
{
    const render::Image image = renderBall(0.03, 1024, 3, 0, true);
    double worst = 0.0;
    for (size_t p = 0; p < image.pixels.size() / 4; ++p) {
        const float* l = &image.layers[p * render::layer::kFloats];
        for (int c = 0; c < 3; ++c) {
            const double sum = double(l[render::layer::kDirect + c]) +
                               l[render::layer::kIndirect + c] + l[render::layer::kEmission + c];
            worst = std::max(worst, std::abs(sum - image.pixels[4 * p + c]) /
                                        std::max(1e-3, double(image.pixels[4 * p + c])));
        }
    }
    EXPECT_LT(worst, 1e-5);
}

TEST(Noise, OneSampleHasNoEstimate)
{
    const render::Image image = renderBall(0.0, 1, 1);
    EXPECT_TRUE(std::isnan(image.noise));
    EXPECT_EQ(image.meanSamples, 1.0);
}
