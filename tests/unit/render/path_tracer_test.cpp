// Multiple scattering (render/src/PathTracer.h) against closed forms and a second method: the white
// furnace, the single-scattering estimator, thread-count independence.
#include <volmorph/render/Renderer.h>

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <cstdio>

using namespace volmorph;
using render::Camera;

namespace {

Camera orthoDown(double width, int pixels)
{
    return Camera(Camera::Projection::Orthographic, Vec3d(0, 0, 5), Vec3d(0, 0, 0), Vec3d(0, 1, 0),
                  40.0, width, pixels, pixels);
}

/// A sphere of radius 0.5 at the origin, density 1 inside: OpenVDB's level set rendered as a body.
openvdb::FloatGrid::Ptr ball(int across)
{
    return openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.5f, openvdb::Vec3f(0.0f),
                                                                    1.0f / float(across), 3.0f);
}

render::Medium body(double extinction, double albedo)
{
    render::Medium medium;
    medium.kind = render::Medium::Kind::LevelSet;
    medium.extinction = extinction;
    medium.albedo = albedo;
    return medium;
}

render::Light environment(double radiance)
{
    render::Light sky;
    sky.type = render::Light::Type::Environment;
    sky.intensity = radiance;
    return sky;
}

} // namespace

TEST(PathTracer, WhiteFurnace)
{
    // Closed form: with albedo 1 and a uniform white sky of radiance 1 and no other light, every
    // path that enters the medium leaves it with radiance 1, so over a transparent background every
    // pixel has RGB / A = 1, whatever the optical thickness.
    const int pixels = 256;
    const auto sphere = ball(128);
    render::RenderSettings settings;
    settings.samples = 2;
    settings.bounces = 10000;
    for (double thickness : {0.5, 10.0}) { // through the centre: extinction times the diameter 1
        const render::Image image =
            render::renderVolume(*sphere, nullptr, orthoDown(1.2, pixels), {environment(1.0)},
                                 body(thickness, 1.0), settings);
        double sum = 0.0, worst = 0.0;
        int counted = 0;
        for (int y = 0; y < pixels; ++y)
            for (int x = 0; x < pixels; ++x) {
                const float* p = image.at(x, y);
                if (p[3] <= 0.05f) continue;
                for (int c = 0; c < 3; ++c) {
                    const double e = std::abs(p[c] / p[3] - 1.0);
                    worst = std::max(worst, e);
                    sum += e;
                }
                ++counted;
            }
        ASSERT_GT(counted, pixels * pixels / 3) << thickness;
        const double mean = sum / (3.0 * counted);
        std::printf("white furnace, thickness %.1f: |RGB/A - 1| mean %.2e, max %.2e over %d "
                    "pixels\n",
                    thickness, mean, worst, counted);
        EXPECT_LE(worst, 0.02) << thickness;
        EXPECT_LE(mean, 0.005) << thickness;
    }
}

TEST(PathTracer, ZeroBouncesAgreeWithTheSingleScatteringEstimator)
{
    // A second method: one scattering event per path (bounces 0), traced, against the deterministic
    // single-scattering march, under one directional light. Alpha is the same exact 1 - T. The
    // march reads the exact transmittance toward the light (no shadow map), the paths estimate it
    // by ratio tracking: both without bias.
    const int pixels = 32;
    const auto sphere = ball(64);
    render::Light sun;
    sun.direction = Vec3d(-1, -1, -0.5);
    sun.intensity = 3.0;
    render::RenderSettings settings;
    settings.samples = 16; // the march is deterministic but for the pixel jitter
    settings.shadowCacheVoxels = 0;
    const render::Medium medium = body(4.0, 0.8);
    const render::Image marched =
        render::renderVolume(*sphere, nullptr, orthoDown(1.2, pixels), {sun}, medium, settings);
    settings.tracePaths = true;
    // The same pixel positions as the march: the same alpha.
    const render::Image tracedFew =
        render::renderVolume(*sphere, nullptr, orthoDown(1.2, pixels), {sun}, medium, settings);
    settings.samples = 1024;
    const render::Image traced =
        render::renderVolume(*sphere, nullptr, orthoDown(1.2, pixels), {sun}, medium, settings);
    double sumMarched = 0.0, sumTraced = 0.0, worstAlpha = 0.0;
    for (int y = 0; y < pixels; ++y)
        for (int x = 0; x < pixels; ++x) {
            sumMarched += marched.at(x, y)[1];
            sumTraced += traced.at(x, y)[1];
            worstAlpha =
                std::max(worstAlpha, double(std::abs(marched.at(x, y)[3] - tracedFew.at(x, y)[3])));
        }
    std::printf("single scattering: marched %.5f, traced %.5f (mean G), alpha diff %.1e\n",
                sumMarched / (pixels * pixels), sumTraced / (pixels * pixels), worstAlpha);
    EXPECT_NEAR(sumTraced / sumMarched, 1.0, 0.01);
    EXPECT_LE(worstAlpha, 1e-3);
}

TEST(PathTracer, MultipleScatteringBrightensAndStaysBelowTheFurnace)
{
    // More bounces add light (each term of the series is non-negative), and with albedo < 1 no
    // pixel exceeds the furnace's bound RGB <= A times the sky's radiance.
    const int pixels = 24;
    const auto sphere = ball(64);
    render::RenderSettings settings;
    settings.samples = 64;
    const render::Medium medium = body(8.0, 0.9);
    double previous = 0.0;
    for (int bounces : {0, 1, 4, 64}) {
        settings.bounces = bounces;
        const render::Image image = render::renderVolume(*sphere, nullptr, orthoDown(1.2, pixels),
                                                         {environment(1.0)}, medium, settings);
        double sum = 0.0;
        for (int y = 0; y < pixels; ++y)
            for (int x = 0; x < pixels; ++x) {
                sum += image.at(x, y)[0];
                EXPECT_LE(image.at(x, y)[0], image.at(x, y)[3] * 1.0001f);
            }
        std::printf("bounces %d: mean R %.4f\n", bounces, sum / (pixels * pixels));
        EXPECT_GT(sum, previous * 1.01) << bounces;
        previous = sum;
    }
}

TEST(PathTracer, FramesDoNotDependOnTheThreadCount)
{
    const auto sphere = ball(48);
    render::Light sun;
    sun.direction = Vec3d(0, -1, -1);
    render::RenderSettings settings;
    settings.samples = 4;
    settings.bounces = 8;
    settings.threads = 1;
    const auto one = render::renderVolume(*sphere, nullptr, orthoDown(1.2, 40),
                                          {sun, environment(0.5)}, body(10.0, 0.9), settings);
    settings.threads = 2;
    const auto two = render::renderVolume(*sphere, nullptr, orthoDown(1.2, 40),
                                          {sun, environment(0.5)}, body(10.0, 0.9), settings);
    EXPECT_EQ(one.pixels, two.pixels);
}

namespace {

/// Single scattering of a uniform sky of radiance 1 by a homogeneous sphere (radius r, extinction
/// sigma, albedo a, isotropic phase) seen along its diameter, by quadrature: the camera ray reaches
/// depth s with transmittance e^(-sigma s), and a point at distance x from the centre sees the sky
/// through e^(-sigma d) where d = -x mu + sqrt(x^2 mu^2 - x^2 + r^2) is its distance to the surface
/// along a direction at cosine mu to the outward radius.
double skySingleScatteringOnAxis(double r, double sigma, double albedo)
{
    const int n = 400;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const double s = (i + 0.5) / n * 2.0 * r, x = std::abs(r - s);
        double sky = 0.0; // the mean over directions of e^(-sigma d)
        for (int j = 0; j < n; ++j) {
            const double mu = -1.0 + (j + 0.5) / n * 2.0;
            const double d = -x * mu + std::sqrt(x * x * mu * mu - x * x + r * r);
            sky += std::exp(-sigma * d) / n;
        }
        sum += sigma * std::exp(-sigma * s) * albedo * sky * (2.0 * r / n);
    }
    return sum;
}

} // namespace

TEST(PathTracer, SkySingleScatteringMatchesQuadrature)
{
    // Delta tracking against a closed form: with bounces 0 a path scatters once and then sees the
    // sky only if delta tracking lets it leave the sphere. One pixel around the axis (0.01 wide).
    const double sigma = 4.0, albedo = 0.7;
    render::RenderSettings settings;
    settings.samples = 65536;
    const render::Image image = render::renderVolume(
        *ball(128), nullptr, orthoDown(0.01, 1), {environment(1.0)}, body(sigma, albedo), settings);
    const double expected = skySingleScatteringOnAxis(0.5, sigma, albedo);
    std::printf("sky single scattering on the axis: traced %.5f, quadrature %.5f\n",
                image.at(0, 0)[0], expected);
    EXPECT_NEAR(image.at(0, 0)[0] / expected, 1.0, 0.025);
    EXPECT_NEAR(image.at(0, 0)[3], 1.0 - std::exp(-sigma), 2e-3);
}
