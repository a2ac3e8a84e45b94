// The layers for compositing (Renderer.h, layer::): direct + indirect + emission = the beauty's
// RGB, in memory and through a half-float EXR; A = volume.A + shadow.A; the depth where alpha
// passes 0.5 against Beer-Lambert, the prop's depth, planar across a perspective image; the EXR's
// channels.
#include <volmorph/render/Output.h>
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include "support/RenderFixtures.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

using namespace volmorph;
using render::Camera;
using render::PropMesh;
namespace layer = render::layer;

namespace {

constexpr double kVoxel = 0.02;

/// A slab of fog from height 0.2 to 0.6 over x in [-1, 0], a floor at 0, a sun at 45 degrees, a
/// glowing medium; seen obliquely so that the image holds the slab, the floor and the empty sky.
struct Shot {
    openvdb::FloatGrid::Ptr density = test::fogSlab(Vec3d(-1, 0.2, -1), Vec3d(0, 0.6, 1), kVoxel);
    render::Medium medium;
    render::RenderSettings settings;
    std::vector<render::Light> lights{test::sunLight(Vec3d(1, -1, 0.3), 3.0)};
    Camera camera{Camera::Projection::Perspective,
                  Vec3d(0.5, 2.5, 4.0),
                  Vec3d(-0.3, 0.3, 0),
                  Vec3d(0, 1, 0),
                  40.0,
                  0.0,
                  48,
                  32};

    Shot()
    {
        medium.extinction = 10.0;
        medium.albedo = 0.8;
        medium.emission = Vec3d(0.2, 0.1, 0.05);
        settings.samples = 4;
        settings.layers = true;
    }
    render::Image render() const
    {
        return render::renderVolume(*density, nullptr, camera, lights, medium, settings);
    }
};

/// A shot traced as paths: four bounces, a sky, the floor.
Shot pathShot(const render::Props& props)
{
    Shot s;
    s.settings.bounces = 4;
    render::Light sky;
    sky.type = render::Light::Type::Environment;
    sky.color = Vec3d(0.3, 0.4, 0.6);
    s.lights.push_back(sky);
    s.settings.props = &props;
    return s;
}

/// Every pixel's direct + indirect + emission against its RGB: within `relative` of the four
/// values' magnitudes (plus `floor`). Returns how many pixels have some light.
int expectLayersAddUp(const render::Image& image, double relative, double floor)
{
    int lit = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const float* px = image.at(x, y);
            const float* l = image.layersAt(x, y);
            for (int c = 0; c < 3; ++c) {
                const double d = l[layer::kDirect + c], i = l[layer::kIndirect + c],
                             e = l[layer::kEmission + c];
                const double scale = std::abs(d) + std::abs(i) + std::abs(e) + std::abs(px[c]);
                EXPECT_NEAR(d + i + e, px[c], relative * scale + floor)
                    << "pixel " << x << ", " << y << " channel " << c;
            }
            lit += px[0] > 0.0f;
        }
    return lit;
}

/// The sum over the image of layer channel `c`.
double layerSum(const render::Image& image, int c)
{
    double sum = 0.0;
    for (size_t p = 0; p < image.pixels.size() / 4; ++p)
        sum += image.layers[p * layer::kFloats + size_t(c)];
    return sum;
}

std::filesystem::path scratch(const char* name)
{
    const auto dir = std::filesystem::temp_directory_path() / "volmorph_layers_test";
    std::filesystem::create_directories(dir);
    return dir / name;
}

} // namespace

TEST(Layers, SingleScatteringsLayersAddUpToTheBeauty)
{
    Shot s;
    const render::Props props({test::floorQuad(0.0, -3, 3, -3, 3)});
    s.settings.props = &props;
    const render::Image image = s.render();
    ASSERT_EQ(image.layers.size(), image.pixels.size() / 4 * layer::kFloats);
    EXPECT_GT(expectLayersAddUp(image, 1e-6, 1e-9), 500);
    // Nothing scatters twice: no indirect light; the emission is emission x (1 - T) in front of
    // the floor, so emission x volume.A.
    EXPECT_EQ(layerSum(image, layer::kIndirect), 0.0);
    for (size_t p = 0; p < image.pixels.size() / 4; ++p) {
        const float* l = &image.layers[p * layer::kFloats];
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(l[layer::kEmission + c], s.medium.emission[c] * l[layer::kVolume + 3],
                        1e-6);
    }
    EXPECT_GT(layerSum(image, layer::kEmission), 1.0);
    EXPECT_GT(layerSum(image, layer::kDirect), 10.0);
}

TEST(Layers, PathTracedLayersAddUpToTheBeauty)
{
    const render::Props props({test::floorQuad(0.0, -3, 3, -3, 3)});
    const render::Image image = pathShot(props).render();
    EXPECT_GT(expectLayersAddUp(image, 1e-6, 1e-9), 500);
    // Light bounces between the slab and the floor, and inside the slab.
    EXPECT_GT(layerSum(image, layer::kIndirect), 0.05 * layerSum(image, layer::kDirect));
    EXPECT_GT(layerSum(image, layer::kEmission), 1.0);
}

TEST(Layers, ThroughAHalfFloatExrTheLayersStillAddUp)
{
    // Each of the four values is rounded to half once: 2^-11 of its magnitude at most (and half's
    // subnormal spacing near 0).
    const render::Props props({test::floorQuad(0.0, -3, 3, -3, 3)});
    for (const bool paths : {false, true}) {
        Shot s = pathShot(props);
        if (!paths) { // single scattering: no sky
            s.lights.pop_back();
            s.settings.bounces = 0;
        }
        const render::Image image = s.render();
        const auto file = scratch(paths ? "paths.exr" : "single.exr");
        render::writeExr(image, s.camera, file, render::ExrOptions{});
        const render::Image back = render::readImage(file);
        ASSERT_EQ(back.layers.size(), image.layers.size());
        EXPECT_GT(expectLayersAddUp(back, 1.01 * std::ldexp(1.0, -11), 1e-7), 500);
        // The depth is float: it comes back exactly.
        for (size_t p = 0; p < image.pixels.size() / 4; ++p)
            EXPECT_EQ(back.layers[p * layer::kFloats + layer::kDepth],
                      image.layers[p * layer::kFloats + layer::kDepth]);
    }
}

TEST(Layers, TheExrNamesItsChannelsAsNukeReadsThem)
{
    Shot s;
    s.settings.samples = 1;
    const auto file = scratch("names.exr");
    render::writeExr(s.render(), s.camera, file, render::ExrOptions{});
    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.nchannels, 19);
    for (const char* name :
         {"R", "G", "B", "A", "volume.R", "volume.G", "volume.B", "volume.A", "direct.R",
          "direct.G", "direct.B", "indirect.R", "indirect.G", "indirect.B", "emission.R",
          "emission.G", "emission.B", "shadow.A", "depth.Z"}) {
        const int c = spec.channelindex(name);
        ASSERT_GE(c, 0) << name;
        EXPECT_EQ(spec.channelformat(c),
                  std::string(name) == "depth.Z" ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF)
            << name;
    }
    // Without layers: RGBA alone.
    s.settings.layers = false;
    render::writeExr(s.render(), s.camera, file, render::ExrOptions{});
    EXPECT_EQ(OIIO::ImageInput::open(file.string())->spec().nchannels, 4);
}

TEST(Layers, AlphaIsTheVolumesPlusTheCatchersShadow)
{
    for (const auto role : {PropMesh::Role::ShadowCatcher, PropMesh::Role::Holdout}) {
        for (const bool paths : {false, true}) {
            Shot s;
            const render::Props props({test::floorQuad(0.0, -3, 3, -3, 3, role)});
            s.settings.props = &props;
            s.settings.tracePaths = paths;
            const render::Image image = s.render();
            double shadow = 0.0;
            for (size_t p = 0; p < image.pixels.size() / 4; ++p) {
                const float* l = &image.layers[p * layer::kFloats];
                EXPECT_NEAR(image.pixels[4 * p + 3], l[layer::kVolume + 3] + l[layer::kShadow],
                            1e-6);
                // The volume layer is the beauty's RGB (nothing but the volume adds colour).
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(image.pixels[4 * p + size_t(c)], l[layer::kVolume + c], 1e-6);
                shadow += l[layer::kShadow];
            }
            if (role == PropMesh::Role::Holdout)
                EXPECT_EQ(shadow, 0.0);
            else
                EXPECT_GT(shadow, 20.0); // the slab's shadow on the catcher
        }
    }
}

TEST(Layers, DepthIsWhereAlphaPassesOneHalfOrTheProps)
{
    // Looking straight down at the slab (density 1 at voxel centres from 0.2 to 0.6, so a linear
    // ramp to 0 over the 0.02 above): optical depth 10 x 0.01 in the ramp, then ln 2 is reached
    // (ln 2 - 0.1) / 10 below 0.6. Beside the slab the floor is at depth 5, past the floor nothing.
    Shot s;
    const render::Props props({test::floorQuad(0.0, 0.5, 3, -3, 3)});
    s.settings.props = &props;
    s.settings.samples = 1;
    s.camera = Camera(Camera::Projection::Orthographic, Vec3d(0, 5, 0), Vec3d(0, 0, 0),
                      Vec3d(0, 0, -1), 40.0, 4.0, 64, 8);
    const double expected = 5.0 - (0.6 - (std::log(2.0) - 0.1) / 10.0);
    for (const bool paths : {false, true}) {
        s.settings.tracePaths = paths;
        const render::Image image = s.render();
        for (int x = 0; x < 64; ++x) {
            const double wx = s.camera.ray(x + 0.5, 4.5).origin.x();
            const float z = image.layersAt(x, 4)[layer::kDepth];
            if (wx > -0.95 && wx < -0.05) {
                EXPECT_NEAR(z, expected, 1e-4) << "x " << wx << " paths " << paths;
            } else if (wx > 0.55) {
                EXPECT_NEAR(z, 5.0, 1e-5) << "x " << wx;
            } else if (wx > 0.05 && wx < 0.45) {
                EXPECT_EQ(z, layer::kNoDepth) << "x " << wx;
            }
        }
    }
    // Perspective, straight down at the floor: the depth is planar, the same in every corner.
    s.camera = Camera(Camera::Projection::Perspective, Vec3d(1.7, 5, 0), Vec3d(1.7, 0, 0),
                      Vec3d(0, 0, -1), 20.0, 0.0, 16, 16);
    s.settings.tracePaths = false;
    const render::Image image = s.render();
    for (const int x : {0, 15})
        for (const int y : {0, 15}) EXPECT_NEAR(image.layersAt(x, y)[layer::kDepth], 5.0, 1e-5);
}

TEST(Layers, MotionBlurAveragesTheLayersAndKeepsTheNearestDepth)
{
    // A still volume seen by a camera that moves over the shutter: the blurred layers still add
    // up, and the depth is the nearest of the times' (the camera nearer the floor at the second).
    Shot s;
    const render::Props props({test::floorQuad(0.0, -3, 3, -3, 3)});
    s.settings.props = &props;
    const Camera later(Camera::Projection::Perspective, Vec3d(0.5, 2.3, 4.0), Vec3d(-0.3, 0.1, 0),
                       Vec3d(0, 1, 0), 40.0, 0.0, 48, 32);
    const std::vector<render::ShutterTime> times{{0.0, s.camera, s.lights},
                                                 {0.01, later, s.lights}};
    const render::Image blurred =
        render::renderMotionBlurred(*s.density, nullptr, nullptr, times, s.medium, s.settings);
    EXPECT_GT(expectLayersAddUp(blurred, 1e-6, 1e-9), 500);
    render::RenderSettings each = s.settings;
    each.samples = 2;
    each.seed = render::shutterSeed(s.settings.seed, 0);
    const render::Image first =
        render::renderVolume(*s.density, nullptr, s.camera, s.lights, s.medium, each);
    each.seed = render::shutterSeed(s.settings.seed, 1);
    const render::Image second =
        render::renderVolume(*s.density, nullptr, later, s.lights, s.medium, each);
    for (size_t p = 0; p < blurred.pixels.size() / 4; ++p) {
        const size_t z = p * layer::kFloats + layer::kDepth;
        EXPECT_EQ(blurred.layers[z], std::min(first.layers[z], second.layers[z]));
        const size_t a = p * layer::kFloats + layer::kVolume + 3;
        EXPECT_FLOAT_EQ(blurred.layers[a], 0.5f * (first.layers[a] + second.layers[a]));
    }
}
