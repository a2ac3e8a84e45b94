#include <volmorph/Voxelize.h>
#include <volmorph/render/Output.h>
#include <volmorph/render/Renderer.h>

#include <gtest/gtest.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

using namespace volmorph;
using render::Camera;

namespace {

const std::filesystem::path kMeshes =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";

VolumeSet sphere(int across)
{
    VoxelizeOptions o;
    o.resolution = across;
    return voxelize(importMesh(kMeshes / "sphere.obj"), o); // radius 0.5 at the origin
}

openvdb::FloatGrid::Ptr sphereFog(int across)
{
    return sphere(across).density;
}

Camera orthoDown(double width, int pixels)
{
    return Camera(Camera::Projection::Orthographic, Vec3d(0, 0, 5), Vec3d(0, 0, 0), Vec3d(0, 1, 0),
                  40.0, width, pixels, pixels);
}

render::Image absorbOnly(const openvdb::FloatGrid& density, const Camera& camera, double extinction,
                         int samples = 16, render::Medium::Kind kind = render::Medium::Kind::Fog,
                         double step = 0.25)
{
    render::Medium medium;
    medium.kind = kind;
    medium.extinction = extinction;
    medium.albedo = 0.0;
    render::RenderSettings settings;
    settings.samples = samples;
    settings.stepVoxels = step;
    return render::renderVolume(density, nullptr, camera, {}, medium, settings);
}

/// Pixel-area average of 1 - exp(-sigma * chord) through a sphere of radius r at the origin,
/// looking along z, over an image `width` world units wide.
double sphereAlpha(int x, int y, int pixels, double width, double sigma, double r)
{
    const int n = 8;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double wx = ((x + (i + 0.5) / n) / pixels - 0.5) * width;
            const double wy = (0.5 - (y + (j + 0.5) / n) / pixels) * width;
            const double d2 = r * r - wx * wx - wy * wy;
            sum += d2 > 0 ? 1.0 - std::exp(-sigma * 2.0 * std::sqrt(d2)) : 0.0;
        }
    return sum / (n * n);
}

} // namespace

TEST(Render, BeerLambertThroughASphere)
{
    // Closed form: alpha = 1 - exp(-sigma * chord) for a homogeneous sphere of radius 0.5:
    // OpenVDB's exact level-set sphere (256 voxels across) rendered as a body with a sharp surface.
    // Silhouette pixels carry the Monte Carlo error of 25 stratified samples over a steep alpha; a
    // jittered step of 1 voxel through a sharp surface is unbiased.
    const int pixels = 256;
    const double width = 1.2, sigma = 4.0;
    const auto ball = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        0.5f, openvdb::Vec3f(0.0f), 1.0f / 256, 3.0f);
    const render::Image image =
        absorbOnly(*ball, orthoDown(width, pixels), sigma, 25, render::Medium::Kind::LevelSet, 1.0);
    double sum = 0.0, worst = 0.0;
    for (int y = 0; y < pixels; ++y)
        for (int x = 0; x < pixels; ++x) {
            const double e =
                std::abs(image.at(x, y)[3] - sphereAlpha(x, y, pixels, width, sigma, 0.5));
            sum += e;
            worst = std::max(worst, e);
            EXPECT_EQ(image.at(x, y)[0], 0.0f); // albedo 0, no emission: no colour
        }
    const double mean = sum / (pixels * pixels);
    std::printf("Beer-Lambert sphere 256x256: alpha mean abs error %.5f, max %.4f\n", mean, worst);
    EXPECT_LE(mean, 0.002);
    EXPECT_LE(worst, 0.03);
}

TEST(Render, FogAlphaMatchesDirectIntegration)
{
    // A second method for fogs: the optical depth integrated along each pixel's central ray with a
    // tiny fixed step, straight from OpenVDB's sampler, against the renderer's jittered march.
    const VolumeSet s = sphere(128);
    const int pixels = 48;
    const double width = 1.2, sigma = 6.0;
    const render::Image image = absorbOnly(*s.density, orthoDown(width, pixels), sigma, 64);
    auto acc = s.density->getConstAccessor();
    double worst = 0.0;
    for (int y = 0; y < pixels; y += 3)
        for (int x = 0; x < pixels; x += 3) {
            // The pixel's average over a 4 x 4 grid of rays.
            double alpha = 0.0;
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) {
                    const double wx = ((x + (i + 0.5) / 4) / pixels - 0.5) * width;
                    const double wy = (0.5 - (y + (j + 0.5) / 4) / pixels) * width;
                    double tau = 0.0;
                    for (double z = -0.6; z < 0.6; z += 0.0005)
                        tau += sigma *
                               openvdb::tools::BoxSampler::sample(
                                   acc, s.density->worldToIndex(Vec3d(wx, wy, z))) *
                               0.0005;
                    alpha += (1.0 - std::exp(-tau)) / 16.0;
                }
            worst = std::max(worst, std::abs(alpha - image.at(x, y)[3]));
        }
    EXPECT_LT(worst, 0.02);
}

TEST(Render, AlphaDoesNotDependOnTheVoxelSize)
{
    // Extinction is per world unit: the same sphere at half the resolution looks the same.
    const Camera camera = orthoDown(1.2, 128);
    const render::Image fine = absorbOnly(*sphereFog(256), camera, 6.0, 4);
    const render::Image coarse = absorbOnly(*sphereFog(128), camera, 6.0, 4);
    double sum = 0.0;
    for (size_t p = 3; p < fine.pixels.size(); p += 4)
        sum += std::abs(fine.pixels[p] - coarse.pixels[p]);
    EXPECT_LE(sum / (fine.pixels.size() / 4), 0.003);
}

TEST(Render, SingleScatteringFromASlab)
{
    // A homogeneous slab of thickness L, lit from straight above by a directional light of
    // irradiance E and seen from above: L_out = albedo p E (1 - exp(-2 sigma L)) / 2, p = 1 / (4
    // pi).
    const double voxel = 0.01, thickness = 0.2, sigma = 5.0, albedo = 0.8;
    auto slab = openvdb::FloatGrid::create(0.0f);
    slab->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    // Voxels 0..19 hold 1; trilinear sampling ramps half a voxel past each end: thickness 20
    // voxels.
    slab->tree().fill(
        openvdb::CoordBBox(openvdb::Coord(-100, -100, 0), openvdb::Coord(100, 100, 19)), 1.0f,
        true);
    render::Light light;
    light.direction = Vec3d(0, 0, -1);
    render::Medium medium;
    medium.extinction = sigma;
    medium.albedo = albedo;
    render::RenderSettings settings;
    settings.samples = 4;
    settings.stepVoxels = 0.25;
    const render::Image image =
        render::renderVolume(*slab, nullptr, orthoDown(0.4, 16), {light}, medium, settings);
    const double expected =
        albedo / (4.0 * M_PI) * (1.0 - std::exp(-2.0 * sigma * thickness)) / 2.0;
    const double alpha = 1.0 - std::exp(-sigma * thickness);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            EXPECT_NEAR(image.at(x, y)[0], expected, 0.02 * expected);
            EXPECT_NEAR(image.at(x, y)[3], alpha, 0.002);
        }
}

TEST(Render, BitIdenticalForAnyThreadCount)
{
    const auto density = sphereFog(64);
    const Camera camera(Camera::Projection::Perspective, Vec3d(1, 0.5, 2), Vec3d(0, 0, 0),
                        Vec3d(0, 1, 0), 40, 1, 96, 64);
    render::Light light;
    light.direction = Vec3d(-1, -1, -0.5);
    render::Medium medium;
    render::RenderSettings settings;
    settings.samples = 3;
    settings.threads = 1;
    const render::Image one =
        render::renderVolume(*density, nullptr, camera, {light}, medium, settings);
    settings.threads = 2;
    const render::Image two =
        render::renderVolume(*density, nullptr, camera, {light}, medium, settings);
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)),
              0);
    // A different frame number draws other samples.
    settings.frame = 1;
    const render::Image other =
        render::renderVolume(*density, nullptr, camera, {light}, medium, settings);
    EXPECT_NE(
        std::memcmp(one.pixels.data(), other.pixels.data(), one.pixels.size() * sizeof(float)), 0);
}

TEST(Render, ExrRoundTripAndAtomicWrite)
{
    render::Image image;
    image.width = 4;
    image.height = 2;
    for (int i = 0; i < 8; ++i)
        image.pixels.insert(image.pixels.end(), {0.1f * i, 0.5f, 1.0f, 0.25f});
    const Camera camera = orthoDown(1.0, 4);
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "volmorph_render_test";
    std::filesystem::create_directories(dir);
    render::ExrOptions options;
    options.frame = 7;
    render::writeExr(image, camera, dir / "a.exr", options);
    const render::Image back = render::readImage(dir / "a.exr");
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 2);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        EXPECT_NEAR(back.pixels[i], image.pixels[i], 1e-3);
    render::writePng(image, dir / "a.png");
    EXPECT_EQ(render::readImage(dir / "a.png").width, 4);
    size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        files += entry.is_regular_file();
    EXPECT_EQ(files, 2u); // no temporary left behind
    EXPECT_THROW(render::writeExr(image, camera, dir / "missing" / "b.exr", options),
                 std::runtime_error);
    EXPECT_FALSE(std::filesystem::exists(dir / "missing"));
    std::filesystem::remove_all(dir);
}

TEST(Render, EmissionIsAlphaTimesTheEmittedRadiance)
{
    // Closed form for an emitting, non-scattering medium: L = integral of T sigma rho E ds
    // = E (1 - T_total) = E alpha, per pixel, whatever the density profile along the ray.
    const auto fog = sphereFog(48);
    render::Medium medium;
    medium.extinction = 3.0;
    medium.albedo = 0.0;
    medium.emission = Vec3d(0.5, 2.0, 0.0);
    render::RenderSettings settings;
    settings.samples = 1;
    const render::Image image =
        render::renderVolume(*fog, nullptr, orthoDown(1.2, 64), {}, medium, settings);
    int covered = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const float* p = image.at(x, y);
            if (p[3] > 0.01f) ++covered;
            EXPECT_NEAR(p[0], 0.5 * p[3], 1e-5) << x << "," << y;
            EXPECT_NEAR(p[1], 2.0 * p[3], 1e-5) << x << "," << y;
            EXPECT_EQ(p[2], 0.0f);
        }
    EXPECT_GT(covered, 1500); // the sphere covers about 55% of the 4096 pixels
}

TEST(Render, ExactOpticalDepthDoesNotDependOnTheStep)
{
    // Optical depth is integrated exactly per interpolation cell, so alpha cannot change with the
    // step (only the scattering quadrature uses it).
    const auto fog = sphereFog(40);
    const Camera camera(Camera::Projection::Perspective, Vec3d(0.3, 0.2, 3), Vec3d(0, 0, 0),
                        Vec3d(0, 1, 0), 30.0, 1.0, 48, 48);
    const render::Image fine = absorbOnly(*fog, camera, 5.0, 1, render::Medium::Kind::Fog, 0.1);
    const render::Image coarse = absorbOnly(*fog, camera, 5.0, 1, render::Medium::Kind::Fog, 4.0);
    double worst = 0.0;
    for (size_t i = 3; i < fine.pixels.size(); i += 4)
        worst = std::max(worst, double(std::abs(fine.pixels[i] - coarse.pixels[i])));
    EXPECT_LT(worst, 1e-6);
}
