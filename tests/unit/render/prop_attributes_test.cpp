// Props with per-vertex attributes (render/Props.h), against closed forms: colours interpolated
// across a floor under a sun (Lambert: reflectance x E / pi), shading normals interpolated
// (E cos / pi), a square moving under motion blur (its alpha the fraction of the shutter it covers
// each point, a triangle profile), and a subject prop in the Volume layer.
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include "support/RenderFixtures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace volmorph;
using render::Camera;
using render::PropMesh;
using test::floorQuad;

namespace {

constexpr int kPixels = 64;
constexpr double kE = 2.0; ///< the sun's irradiance

/// Looking straight down at the floor from above: 64 pixels over 2 world units about the origin.
Camera down()
{
    return Camera(Camera::Projection::Orthographic, Vec3d(0, 5, 0), Vec3d(0, 0, 0), Vec3d(0, 0, -1),
                  40.0, 2.0, kPixels, kPixels);
}

/// An empty fog grid: props alone.
openvdb::FloatGrid::Ptr nothing()
{
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.02));
    return grid;
}

render::Image shoot(const render::Props& props, bool paths, bool layers = false)
{
    render::RenderSettings s;
    s.samples = 1;
    s.tracePaths = paths;
    s.props = &props;
    s.layers = layers;
    return render::renderVolume(*nothing(), nullptr, down(), {test::sunLight(Vec3d(0, -1, 0), kE)},
                                render::Medium{}, s);
}

/// A reflectance linear in x and z: barycentric interpolation reproduces it on every triangle.
Vec3d linearColour(double x, double z)
{
    return Vec3d(0.5 + 0.2 * x, 0.4 + 0.1 * z, 0.3 + 0.1 * x - 0.05 * z);
}

} // namespace

TEST(PropAttributes, VertexColoursAreInterpolatedAndLitAsLambert)
{
    PropMesh floor = floorQuad(0.0, -1, 1, -1, 1);
    for (const Vec3f& p : floor.points) floor.colors.emplace_back(linearColour(p.x(), p.z()));
    const render::Props props({floor});
    for (const bool paths : {false, true}) {
        const render::Image image = shoot(props, paths);
        for (int py = 4; py < kPixels; py += 9)
            for (int px = 3; px < kPixels; px += 7) {
                const Vec3d at = down().ray(px + 0.5, py + 0.5).origin;
                const Vec3d expected = linearColour(at.x(), at.z()) * (kE / M_PI);
                const float* pixel = image.at(px, py);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(pixel[c], expected[c], 1e-5) << px << "," << py << " " << paths;
                EXPECT_EQ(pixel[3], 1.0f);
            }
    }
}

TEST(PropAttributes, ShadingNormalsAreInterpolatedAcrossTheTriangles)
{
    // Normals (x, 1, 0) at the corners: interpolated, (x, 1, 0) everywhere, so a sun straight
    // down lights x at cos = 1 / sqrt(1 + x^2) though the floor is flat.
    PropMesh floor = floorQuad(0.0, -1, 1, -1, 1);
    for (const Vec3f& p : floor.points) floor.normals.emplace_back(p.x(), 1.0f, 0.0f);
    const render::Props props({floor});
    for (const bool paths : {false, true}) {
        const render::Image image = shoot(props, paths);
        for (int px = 2; px < kPixels; px += 5) {
            const double x = down().ray(px + 0.5, 32.5).origin.x();
            const double cosine = 1.0 / std::sqrt(1.0 + x * x);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(image.at(px, 32)[c], floor.color[c] * kE / M_PI * cosine, 1e-5)
                    << "x " << x << " paths " << paths;
        }
    }
    // Normals that point below the floor are turned to the side the ray arrives from.
    for (Vec3f& n : floor.normals) n = -n;
    const render::Image flipped = shoot(render::Props({floor}), false);
    const render::Image image = shoot(props, false);
    for (int px = 0; px < kPixels; ++px) EXPECT_EQ(flipped.at(px, 32)[0], image.at(px, 32)[0]);
}

TEST(PropAttributes, MovedPropsTravelAlongTheirVelocities)
{
    PropMesh square = floorQuad(0.0, -0.25, 0.25, -0.25, 0.25);
    const render::Props still({square});
    EXPECT_FALSE(still.moves());
    square.velocities.assign(4, Vec3f(0.5f, 0.0f, -1.0f));
    const render::Props props({square, floorQuad(-1.0, -2, 2, -2, 2)});
    EXPECT_TRUE(props.moves());
    const auto moved = props.moved(0.2);
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(moved->mesh(0).points[i],
                  Vec3f(Vec3d(square.points[i]) + Vec3d(0.5, 0.0, -1.0) * 0.2));
        EXPECT_EQ(moved->mesh(1).points[i], props.mesh(1).points[i]); // no velocity: stays
    }
    PropMesh wrong = square;
    wrong.colors.resize(3);
    EXPECT_THROW(render::Props({wrong}), std::invalid_argument);
}

TEST(PropAttributes, AMovingSquareBlursIntoTheFractionOfTheShutterItCovers)
{
    // A square 0.5 across moving 0.5 world units per second along x, the shutter open one second
    // about the frame: x is covered while |x - 0.5 s| < 0.25, s in [-0.5, 0.5], for a fraction
    // max(0, 1 - 2 |x|) of it.
    PropMesh square = floorQuad(0.0, -0.25, 0.25, -0.25, 0.25);
    square.velocities.assign(4, Vec3f(0.5f, 0.0f, 0.0f));
    const render::Props props({square});
    constexpr int kTimes = 16;
    std::vector<render::ShutterTime> times;
    for (double s : render::shutterOffsets(-0.5, 0.5, kTimes))
        times.push_back({s, down(), {test::sunLight(Vec3d(0, -1, 0), kE)}});
    render::RenderSettings settings;
    settings.samples = 4 * kTimes;
    settings.centreSingleSample = false;
    settings.props = &props;
    const render::Image image = render::renderMotionBlurred(*nothing(), nullptr, nullptr, times,
                                                            render::Medium{}, settings);
    double squared = 0.0, covered = 0.0;
    const double pixel = 2.0 / kPixels;
    for (int px = 0; px < kPixels; ++px) {
        const double x = down().ray(px + 0.5, 32.5).origin.x();
        const double alpha = image.at(px, 32)[3];
        const double expected = std::max(0.0, 1.0 - 2.0 * std::abs(x));
        // Each time's square, seen over a pixel, is within a pixel's share of the continuous mean.
        EXPECT_NEAR(alpha, expected, 1.0 / kTimes + 2.0 * pixel) << "x " << x;
        squared += (alpha - expected) * (alpha - expected);
        covered += alpha * pixel;
    }
    EXPECT_LT(std::sqrt(squared / kPixels), 0.03);
    EXPECT_NEAR(covered, 0.5, 0.01); // the square's width, whatever the motion
    // Pixel 31 ([-1/32, 0] in x) is covered at every time but the first, by half then.
    EXPECT_NEAR(image.at(31, 32)[3], 1.0 - 0.5 / kTimes, 1e-6);
}

TEST(PropAttributes, ASubjectPropIsInTheVolumeLayer)
{
    PropMesh square = floorQuad(0.5, -0.25, 0.25, -0.25, 0.25);
    square.subject = true;
    const render::Props props({square, floorQuad(0.0, -2, 2, -2, 2)});
    const render::Image image = shoot(props, false, true);
    namespace layer = render::layer;
    const float* onSubject = image.layersAt(32, 32);
    EXPECT_EQ(onSubject[layer::kVolume + 3], 1.0f);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(onSubject[layer::kVolume + c], image.at(32, 32)[c]);
    const float* onFloor = image.layersAt(2, 32);
    EXPECT_EQ(onFloor[layer::kVolume + 3], 0.0f);
    EXPECT_EQ(onFloor[layer::kVolume + 0], 0.0f);
    EXPECT_GT(image.at(2, 32)[0], 0.0f); // the floor is in the beauty
}
