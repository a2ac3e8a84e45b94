// Props (render/Props.h) against closed forms: a Lambertian floor under a sun, the shadow of a slab
// of known optical depth on it (Beer-Lambert), a shadow catcher's matte, a holdout's alpha, and a
// prop's shadow on the volume against the exact march and the path tracer.
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include "support/RenderFixtures.h"

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace volmorph;
using render::Camera;
using render::PropMesh;
using render::Ray;
using test::floorQuad;

namespace {

constexpr double kVoxel = 0.02;

openvdb::FloatGrid::Ptr slab(Vec3d lo, Vec3d hi)
{
    return test::fogSlab(lo, hi, kVoxel);
}

/// Looking straight down at the floor from above: 64 pixels over 2 world units, centred at x.
Camera downAt(double x)
{
    return Camera(Camera::Projection::Orthographic, Vec3d(x, 5, 0), Vec3d(x, 0, 0), Vec3d(0, 0, -1),
                  40.0, 2.0, 64, 64);
}

render::Light sun(const Vec3d& travel, double intensity)
{
    return test::sunLight(travel, intensity);
}

/// The pixel of row 32 whose ray passes nearest world x (an orthographic camera).
const float* atX(const render::Image& image, const Camera& camera, double x)
{
    int best = 0;
    for (int px = 1; px < image.width; ++px)
        if (std::abs(camera.ray(px + 0.5, 32.5).origin.x() - x) <
            std::abs(camera.ray(best + 0.5, 32.5).origin.x() - x))
            best = px;
    return image.at(best, 32);
}

struct Shot {
    openvdb::FloatGrid::Ptr density;
    render::Medium medium;
    render::RenderSettings settings;
    std::vector<render::Light> lights;
};

/// A slab 0.1 thick at heights 0.5 to 0.6 over x in [-1, -0.5], a sun travelling down at 45
/// degrees toward +x: its shadow falls on the floor over x in about [-0.5, 0], where the sun's
/// ray crosses the slab for 0.1 sqrt(2).
Shot slabShot()
{
    Shot s;
    // Voxel centres from 0.5 to 0.58: with the trilinear ramps, 0.1 of optical thickness across.
    s.density = slab(Vec3d(-1.0, 0.5, -1.0), Vec3d(-0.5, 0.58, 1.0));
    s.medium.extinction = 10.0;
    s.medium.albedo = 0.0;
    s.settings.samples = 1;
    s.lights = {sun(Vec3d(1, -1, 0), 3.0)};
    return s;
}

} // namespace

TEST(Props, ASunOnAFloorAndTheSlabsShadowAreLambertAndBeerLambert)
{
    Shot s = slabShot();
    const render::Props props({floorQuad(0.0, -3, 3, -3, 3)});
    s.settings.props = &props;
    const double cosine = 1.0 / std::sqrt(2.0);
    const Vec3d lit = Vec3d(0.5, 0.6, 0.7) / M_PI * 3.0 * cosine;
    const double T = std::exp(-10.0 * 0.1 * std::sqrt(2.0));
    for (const bool paths : {false, true}) {
        s.settings.tracePaths = paths;
        const render::Image image =
            render::renderVolume(*s.density, nullptr, downAt(0.0), s.lights, s.medium, s.settings);
        const float* open = atX(image, downAt(0.0), 0.5);
        const float* shadow = atX(image, downAt(0.0), -0.25);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(open[c], lit[c], 1e-5 * lit[c]) << "paths " << paths;
            EXPECT_NEAR(shadow[c], lit[c] * T, 1e-4 * lit[c]) << "paths " << paths;
        }
        EXPECT_EQ(open[3], 1.0f);
        EXPECT_EQ(shadow[3], 1.0f);
    }
}

TEST(Props, AShadowCatchersMatteIsTheShadowsDepth)
{
    Shot s = slabShot();
    const render::Props props({floorQuad(0.0, -3, 3, -3, 3, PropMesh::Role::ShadowCatcher)});
    s.settings.props = &props;
    const double T = std::exp(-10.0 * 0.1 * std::sqrt(2.0));
    const render::Image image =
        render::renderVolume(*s.density, nullptr, downAt(0.0), s.lights, s.medium, s.settings);
    const float* open = atX(image, downAt(0.0), 0.5);
    const float* shadow = atX(image, downAt(0.0), -0.25);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(open[c], 0.0f);
        EXPECT_EQ(shadow[c], 0.0f);
    }
    EXPECT_EQ(open[3], 0.0f);
    EXPECT_NEAR(shadow[3], 1.0 - T, 1e-4);
}

TEST(Props, AHoldoutInFrontOfTheVolumeZeroesItsAlpha)
{
    Shot s = slabShot();
    s.medium.albedo = 0.8;
    s.lights = {sun(Vec3d(0, -1, 0), 3.0)}; // overhead: the holdout's shadow falls under it
    // A holdout above the slab's left half, between it and the camera.
    const render::Props props({floorQuad(1.0, -1.2, -0.75, -3, 3, PropMesh::Role::Holdout)});
    const render::Image plain =
        render::renderVolume(*s.density, nullptr, downAt(-0.75), s.lights, s.medium, s.settings);
    s.settings.props = &props;
    const render::Image cut =
        render::renderVolume(*s.density, nullptr, downAt(-0.75), s.lights, s.medium, s.settings);
    const float* behind = atX(cut, downAt(-0.75), -0.9);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(behind[c], 0.0f);
    EXPECT_GT(atX(plain, downAt(-0.75), -0.9)[3], 0.5f);
    // Beside the holdout the volume is as it was.
    const float* beside = atX(cut, downAt(-0.75), -0.6);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(beside[c], atX(plain, downAt(-0.75), -0.6)[c]);
}

TEST(Props, APropsShadowDarkensTheVolume)
{
    // An opaque quad above the slab's left part, between it and a sun overhead: there the slab
    // receives no direct light, and its single scattering is 0 (no emission); beside it, the same
    // as without the quad, to the bit. Seen from below, by the shadow map, the exact march and the
    // path tracer (bounces 0).
    Shot s = slabShot();
    s.medium.albedo = 0.8;
    s.lights = {sun(Vec3d(0, -1, 0), 3.0)};
    const render::Props props({floorQuad(1.0, -1.5, -0.75, -3, 3)});
    const Camera up(Camera::Projection::Orthographic, Vec3d(-0.75, -5, 0), Vec3d(-0.75, 0, 0),
                    Vec3d(0, 0, 1), 40.0, 2.0, 64, 64);
    for (const int method : {0, 1, 2}) {
        s.settings.shadowCacheVoxels = method == 0 ? 1 : 0;
        s.settings.tracePaths = method == 2;
        s.settings.samples = method == 2 ? 16 : 1;
        s.settings.props = nullptr; // the reference: the same method without the quad
        const render::Image plain =
            render::renderVolume(*s.density, nullptr, up, s.lights, s.medium, s.settings);
        s.settings.props = &props;
        const render::Image image =
            render::renderVolume(*s.density, nullptr, up, s.lights, s.medium, s.settings);
        int dark = 0, lit = 0;
        for (int px = 0; px < 64; ++px) {
            const double x = up.ray(px + 0.5, 32.5).origin.x();
            const float* p = image.at(px, 32);
            const float* q = plain.at(px, 32);
            if (x > -0.97 && x < -0.8) { // under the quad
                ++dark;
                EXPECT_GT(q[0], 0.04f);
                for (int c = 0; c < 3; ++c) EXPECT_LT(p[c], 1e-6f) << "method " << method;
            } else if (x > -0.7 && x < -0.53) { // beside it
                ++lit;
                for (int c = 0; c < 3; ++c) EXPECT_EQ(p[c], q[c]) << "method " << method;
            }
        }
        EXPECT_GT(dark, 4);
        EXPECT_GT(lit, 4);
    }
}

TEST(Props, AFloorUnderAUniformSkyReflectsItsColourTimesTheSky)
{
    // A white furnace for surfaces: a diffuse floor under a sky of radiance L from every direction
    // (and nothing else, the volume empty) sends back color x L exactly, at any sample count.
    const auto empty = openvdb::FloatGrid::create(0.0f);
    empty->setTransform(openvdb::math::Transform::createLinearTransform(kVoxel));
    const render::Props props({floorQuad(0.0, -3, 3, -3, 3)});
    render::Light sky;
    sky.type = render::Light::Type::Environment;
    sky.intensity = 0.5;
    render::Medium medium;
    render::RenderSettings settings;
    settings.samples = 4;
    settings.props = &props;
    const render::Image image =
        render::renderVolume(*empty, nullptr, downAt(0.0), {sky}, medium, settings);
    const Vec3d expected = Vec3d(0.5, 0.6, 0.7) * 0.5;
    for (const double x : {-0.5, 0.0, 0.7}) {
        const float* p = atX(image, downAt(0.0), x);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c], expected[c], 1e-6);
        EXPECT_EQ(p[3], 1.0f);
    }
}

TEST(Props, ASoftSunsPenumbraIsHeightTimesAngle)
{
    // An opaque sphere (a level set of constant density) of radius 0.5 centred 1 above a floor,
    // under a sun overhead of angular diameter a: its shadow's edge on the floor is a penumbra of
    // full width h a (h = 1, the silhouette's height). Seen from a camera under the sphere, along
    // one row across the edge; the 10-90% width of a disc's straight-edge penumbra is 0.687 of
    // its full width.
    const double a = 6.0 * M_PI / 180.0;
    const auto ball = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        0.5f, openvdb::Vec3f(0, 1, 0), 0.01f, 3.0f);
    const render::Props props({floorQuad(0.0, -3, 3, -3, 3)});
    render::Light light = sun(Vec3d(0, -1, 0), 1.0);
    light.angle = a;
    render::Medium medium;
    medium.kind = render::Medium::Kind::LevelSet;
    medium.extinction = 400.0;
    render::RenderSettings settings;
    settings.samples = 1024;
    settings.props = &props;
    // Beside the sphere, below it, looking down at the edge on the x axis: the row runs along x.
    const Camera camera(Camera::Projection::Perspective, Vec3d(0.5, 0.3, -0.35), Vec3d(0.5, 0, 0),
                        Vec3d(0, 1, 0), 30.0, 0.0, 256, 1);
    const render::Image image =
        render::renderVolume(*ball, nullptr, camera, {light}, medium, settings);
    // Visible fraction of the sun against floor x, outward across the edge.
    const double lit = 0.6 / M_PI; // the floor's red reflectance / pi, irradiance 1
    std::vector<std::pair<double, double>> profile;
    for (int px = 0; px < 256; ++px) {
        const Ray ray = camera.ray(px + 0.5, 0.5);
        const double t = -ray.origin.y() / ray.direction.y();
        const Vec3d floor = ray.origin + ray.direction * t;
        profile.emplace_back(std::hypot(floor.x(), floor.z()), image.at(px, 0)[1] / lit);
    }
    std::sort(profile.begin(), profile.end());
    auto crossing = [&](double level) { // the first x where the fraction reaches `level`
        for (size_t i = 1; i < profile.size(); ++i)
            if (profile[i].second >= level && profile[i - 1].second < level) {
                const auto& [x0, f0] = profile[i - 1];
                const auto& [x1, f1] = profile[i];
                return x0 + (level - f0) / (f1 - f0) * (x1 - x0);
            }
        return 0.0;
    };
    const double width = (crossing(0.9) - crossing(0.1)) / 0.687;
    std::printf("penumbra: %.4f world units wide, h a = %.4f\n", width, a);
    EXPECT_NEAR(width, a, 0.1 * a);
    EXPECT_NEAR(0.5 * (crossing(0.9) + crossing(0.1)), 0.5, 0.01); // centred on the silhouette
    EXPECT_NEAR(profile.front().second, 0.0, 1e-6);                // the umbra
    EXPECT_NEAR(profile.back().second, 1.0, 1e-3);                 // full sun
}
