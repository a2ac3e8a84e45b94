// The HDR sky (render/EnvironmentMap.h): its orientation, its sampling density against its own
// definition, and in the renderer a uniform map against the constant sky and a black map with a
// small bright disc against a soft sun of equal irradiance and angle.
#include <volmorph/render/EnvironmentMap.h>
#include <volmorph/render/Output.h>
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include "support/RenderFixtures.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

using namespace volmorph;
using render::Camera;
using render::EnvironmentMap;

namespace {

/// The unit direction at the centre of pixel (i, j) of a width x height lat-long map.
Vec3d pixelCentre(int i, int j, int width, int height)
{
    const double theta = M_PI * (j + 0.5) / height, phi = 2.0 * M_PI * ((i + 0.5) / width - 0.5);
    return Vec3d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
}

/// A black width x height map with radiance `L` in every pixel whose centre lies within `radius`
/// (radians) of unit direction `centre`; `irradiance` gets what a surface facing `centre` receives
/// from it (each pixel's radiance x cosine x solid angle, at its centre).
std::vector<float> discMap(int width, int height, const Vec3d& centre, double radius, double L,
                           double& irradiance)
{
    std::vector<float> rgb(size_t(3 * width * height), 0.0f);
    irradiance = 0.0;
    for (int j = 0; j < height; ++j) {
        const double solidAngle =
            2.0 * M_PI / width * (std::cos(M_PI * j / height) - std::cos(M_PI * (j + 1) / height));
        for (int i = 0; i < width; ++i) {
            const double cosine = pixelCentre(i, j, width, height).dot(centre);
            if (cosine < std::cos(radius)) continue;
            for (int c = 0; c < 3; ++c) rgb[size_t(3 * (j * width + i) + c)] = float(L);
            irradiance += L * cosine * solidAngle;
        }
    }
    return rgb;
}

/// A slab of fog over part of a floor, seen from above at an angle; four bounces.
struct SkyShot {
    openvdb::FloatGrid::Ptr density = test::fogSlab(Vec3d(-1, 0.3, -1), Vec3d(0, 0.6, 1), 0.02);
    render::Props props{{test::floorQuad(0.0, -3, 3, -3, 3)}};
    render::Medium medium;
    render::RenderSettings settings;
    Camera camera{Camera::Projection::Perspective,
                  Vec3d(0.8, 2.5, 3.5),
                  Vec3d(-0.3, 0.2, 0),
                  Vec3d(0, 1, 0),
                  45.0,
                  0.0,
                  40,
                  28};

    SkyShot()
    {
        medium.extinction = 6.0;
        medium.albedo = 0.9;
        settings.samples = 256;
        settings.bounces = 4;
        settings.props = &props;
    }
    render::Image render(const std::vector<render::Light>& lights) const
    {
        return render::renderVolume(*density, nullptr, camera, lights, medium, settings);
    }
};

/// Mean absolute RGB difference over mean RGB of `b`, over pixels where b's alpha is above 0.1.
double meanRelativeDifference(const render::Image& a, const render::Image& b)
{
    double diff = 0.0, sum = 0.0;
    for (size_t p = 0; p < b.pixels.size() / 4; ++p) {
        if (b.pixels[4 * p + 3] <= 0.1f) continue;
        for (size_t c = 0; c < 3; ++c) {
            diff += std::abs(double(a.pixels[4 * p + c]) - double(b.pixels[4 * p + c]));
            sum += std::abs(double(b.pixels[4 * p + c]));
        }
    }
    return diff / sum;
}

double meanOf(const render::Image& image, size_t channel)
{
    double sum = 0.0;
    for (size_t p = channel; p < image.pixels.size(); p += 4) sum += image.pixels[p];
    return sum / double(image.pixels.size() / 4);
}

/// The mean of `channel` over quarter (qx, qy) of the image.
double quarterMean(const render::Image& image, int qx, int qy, size_t channel)
{
    double sum = 0.0;
    int n = 0;
    for (int y = qy * image.height / 2; y < (qy + 1) * image.height / 2; ++y)
        for (int x = qx * image.width / 2; x < (qx + 1) * image.width / 2; ++x, ++n)
            sum += image.at(x, y)[channel];
    return sum / n;
}

} // namespace

TEST(EnvironmentMap, ItsCentreLooksAlongXAndAQuarterOnAlongZ)
{
    // One bright pixel at a time; the map is 8 x 4 (columns 45 degrees of azimuth from -180,
    // rows 45 degrees of polar angle from +y).
    for (const auto& [i, j, direction] :
         {std::tuple{4, 1, Vec3d(1, 0.2, 0.01)}, std::tuple{6, 2, Vec3d(-0.2, -0.2, 1)},
          std::tuple{0, 0, Vec3d(-1, 1.5, -0.2)}, std::tuple{2, 3, Vec3d(0.3, -1.5, -0.5)}}) {
        std::vector<float> rgb(96, 0.0f);
        rgb[size_t(3 * (j * 8 + i))] = 1.0f;
        const EnvironmentMap map(8, 4, rgb);
        EXPECT_EQ(map.radiance(direction.unit()).x(), 1.0) << i << ", " << j;
        EXPECT_EQ(map.radiance(-direction.unit()).x(), 0.0) << i << ", " << j;
    }
}

TEST(EnvironmentMap, SamplesFollowTheDensityTheyReport)
{
    // A map of smoothly varying brightness with a hot spot: each sample's reported density is
    // pdf() of its direction; the density integrates to 1 over the sphere (constant over each
    // pixel: the sum of density x solid angle); the share of samples falling in the hot spot is its
    // share of the power.
    const int w = 64, h = 32;
    std::vector<float> rgb(size_t(3 * w * h));
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            for (int c = 0; c < 3; ++c)
                rgb[size_t(3 * (j * w + i) + c)] =
                    float(0.2 + 0.1 * c + 0.5 * std::sin(0.3 * i) * std::sin(0.3 * i) +
                          (i == 40 && j == 10 ? 500.0 : 0.0));
    const EnvironmentMap map(w, h, rgb);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int n = 200000;
    int hot = 0;
    for (int k = 0; k < n; ++k) {
        double pdf;
        const Vec3d d = map.sample(u(rng), u(rng), pdf);
        ASSERT_NEAR(d.length(), 1.0, 1e-12);
        ASSERT_NEAR(pdf, map.pdf(d), 1e-9 * pdf);
        hot += map.radiance(d).x() > 100.0;
    }
    const Vec3d hotCentre = pixelCentre(40, 10, w, h);
    const double hotSolidAngle =
        2.0 * M_PI / w * (std::cos(M_PI * 10 / h) - std::cos(M_PI * 11 / h));
    const double hotShare = map.pdf(hotCentre) * hotSolidAngle;
    EXPECT_NEAR(double(hot) / n, hotShare, 4.0 * std::sqrt(hotShare * (1 - hotShare) / n));
    double integral = 0.0;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            integral += map.pdf(pixelCentre(i, j, w, h)) * 2.0 * M_PI / w *
                        (std::cos(M_PI * j / h) - std::cos(M_PI * (j + 1) / h));
    EXPECT_NEAR(integral, 1.0, 1e-9);
    // A map of one colour is sampled uniformly.
    const EnvironmentMap grey(16, 8, std::vector<float>(16 * 8 * 3, 0.7f));
    EXPECT_NEAR(grey.pdf(Vec3d(0.3, 0.9, 0.1).unit()), 1.0 / (4.0 * M_PI), 1e-12);
}

TEST(EnvironmentMap, AMapIsReadThroughOpenImageIO)
{
    const auto file = std::filesystem::temp_directory_path() / "volmorph_sky_test.exr";
    std::vector<float> rgb(32 * 16 * 3, 0.25f);
    rgb[3 * (32 * 5 + 20) + 1] = 4.0f;
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out->open(file.string(), OIIO::ImageSpec(32, 16, 3, OIIO::TypeDesc::FLOAT)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
    out->close();
    const auto map = EnvironmentMap::read(file);
    EXPECT_EQ(map->width(), 32);
    EXPECT_EQ(map->height(), 16);
    EXPECT_EQ(map->radiance(pixelCentre(20, 5, 32, 16)), Vec3d(0.25, 4.0, 0.25));
    EXPECT_THROW(EnvironmentMap::read(file.string() + ".missing"), std::runtime_error);
}

TEST(EnvironmentMap, AUniformMapEqualsTheConstantSky)
{
    // The same sky, constant or from a map of one colour (drawn uniformly, weighed against the
    // phase function's and the floor's cosine's choices): the same image within noise (the means
    // of each quarter of it), and the same alpha exactly (lights do not change it).
    SkyShot shot;
    shot.settings.samples = 64;
    render::Light constant;
    constant.type = render::Light::Type::Environment;
    constant.color = Vec3d(0.6, 0.7, 0.9);
    render::Light mapped = constant;
    mapped.map = std::make_shared<const EnvironmentMap>(16, 8, std::vector<float>(384, 1.0f));
    const render::Image a = shot.render({constant});
    const render::Image b = shot.render({mapped});
    std::printf("uniform map against the constant sky: image means %.5f / %.5f (G), mean "
                "relative difference per pixel (noise, 64 samples) %.4f\n",
                meanOf(b, 1), meanOf(a, 1), meanRelativeDifference(b, a));
    for (int qx = 0; qx < 2; ++qx)
        for (int qy = 0; qy < 2; ++qy)
            for (size_t c = 0; c < 3; ++c) {
                const double ma = quarterMean(a, qx, qy, c), mb = quarterMean(b, qx, qy, c);
                EXPECT_NEAR(mb, ma, 0.01 * ma) << "quarter " << qx << qy << " channel " << c;
            }
    EXPECT_EQ(meanOf(a, 3), meanOf(b, 3));
}

TEST(EnvironmentMap, ASmallBrightDiscIsASunOfEqualIrradianceAndAngle)
{
    // A black map but for a disc of angular diameter 4 degrees, 40 degrees above the horizon: the
    // same image as a soft sun of that angle and the disc's irradiance, at equal samples.
    const Vec3d toward = Vec3d(0.5, std::tan(40.0 * M_PI / 180.0), -0.6).unit();
    const double angle = 4.0 * M_PI / 180.0;
    double irradiance = 0.0;
    std::vector<float> rgb = discMap(1024, 512, toward, 0.5 * angle, 1000.0, irradiance);
    render::Light sky;
    sky.type = render::Light::Type::Environment;
    sky.map = std::make_shared<const EnvironmentMap>(1024, 512, std::move(rgb));
    render::Light sun = test::sunLight(-toward, irradiance);
    sun.angle = angle;
    SkyShot shot;
    const render::Image fromMap = shot.render({sky});
    const render::Image fromSun = shot.render({sun});
    const double difference = meanRelativeDifference(fromMap, fromSun);
    std::printf("disc map (irradiance %.4f) against a sun: image means %.5f / %.5f (G), mean "
                "relative difference %.4f\n",
                irradiance, meanOf(fromMap, 1), meanOf(fromSun, 1), difference);
    EXPECT_NEAR(meanOf(fromMap, 1), meanOf(fromSun, 1), 0.01 * meanOf(fromSun, 1));
    EXPECT_LT(difference, 0.02);
}
