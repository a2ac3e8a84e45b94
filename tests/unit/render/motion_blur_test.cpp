// Eulerian motion blur (renderMotionBlurred) against the mean of 64 unblurred renders at the same
// shutter times, each of the volume moved exactly (its transform translated or turned, not
// resampled): a translating sphere, where Eulerian blur is exact; a turning bar, where it is not;
// and a still sphere under a panning camera.
#include <volmorph/Voxelize.h>
#include <volmorph/render/Renderer.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace volmorph;
using render::Camera;

namespace {

const std::filesystem::path kMeshes =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";

constexpr int kPixels = 64, kTimes = 64;

openvdb::FloatGrid::Ptr sphereFog()
{
    VoxelizeOptions o;
    o.resolution = 40;
    return voxelize(importMesh(kMeshes / "sphere.obj"), o).density; // radius 0.5 at the origin
}

/// A bar along x, 1 x 0.3 x 0.3 world units about the origin, 60 voxels long.
openvdb::FloatGrid::Ptr barFog()
{
    Mesh bar = importMesh(kMeshes / "cube.obj"); // the unit cube about the origin
    for (Vec3f& p : bar.points) p = Vec3f(p.x(), 0.3f * p.y(), 0.3f * p.z());
    VoxelizeOptions o;
    o.resolution = 60;
    return voxelize(bar, o).density;
}

Camera orthoDown(const Vec3d& at)
{
    return Camera(Camera::Projection::Orthographic, at + Vec3d(0, 0, 5), at, Vec3d(0, 1, 0), 40.0,
                  2.5, kPixels, kPixels);
}

render::Medium medium()
{
    render::Medium m;
    m.extinction = 6.0;
    m.albedo = 0.7;
    return m;
}

/// Samples per pixel at each shutter time, jittered over the pixel, in the blurred image and in
/// each sub-frame alike: sub-frame k is seeded as the blur seeds its time k, so that both see the
/// same sample positions and differ only by how the volume was moved.
constexpr int kSamplesPerTime = 2;

render::RenderSettings settings(int samples)
{
    render::RenderSettings s;
    s.samples = samples;
    s.centreSingleSample = false;
    return s;
}

/// Sub-frame k's settings.
render::RenderSettings subFrame(int k)
{
    render::RenderSettings s = settings(kSamplesPerTime);
    s.seed = render::shutterSeed(s.seed, size_t(k));
    return s;
}

/// A velocity grid of `v` (world units per second) over the sphere's neighbourhood, 2 world units
/// each way: what the density can reach.
openvdb::Vec3SGrid::Ptr uniformVelocity(const openvdb::FloatGrid& like, const Vec3d& v)
{
    auto grid = openvdb::Vec3SGrid::create(Vec3f(0.0f));
    grid->setTransform(like.transform().copy());
    const openvdb::Coord r = like.transform().worldToIndexCellCentered(Vec3d(2.0));
    grid->fill(openvdb::CoordBBox(-r, r), Vec3f(v), true);
    return grid;
}

/// A turn about z at `omega` (radians per second): w x p at every voxel within 0.8 world units of
/// the axis and 0.3 of the xy plane (what the bar can reach).
openvdb::Vec3SGrid::Ptr turningVelocity(const openvdb::FloatGrid& like, double omega)
{
    auto grid = openvdb::Vec3SGrid::create(Vec3f(0.0f));
    grid->setTransform(like.transform().copy());
    const openvdb::Coord r = like.transform().worldToIndexCellCentered(Vec3d(0.8, 0.8, 0.3));
    auto acc = grid->getAccessor();
    for (auto c = openvdb::CoordBBox(-r, r).begin(); c; ++c) {
        const Vec3d p = like.indexToWorld(*c);
        acc.setValue(*c, Vec3f(Vec3d(0.0, 0.0, omega).cross(p)));
    }
    return grid;
}

/// The shutter's times: [-0.5, 0.5] s, evenly spread.
double timeAt(int k)
{
    return -0.5 + (k + 0.5) / kTimes;
}

/// The mean |a - b| over pixels where either's alpha exceeds 0.01, relative to b's mean there,
/// per channel (RGB and A).
double meanRelativeDifference(const render::Image& a, const render::Image& b)
{
    double worst = 0.0;
    for (int c = 0; c < 4; ++c) {
        double diff = 0.0, sum = 0.0;
        for (int y = 0; y < kPixels; ++y)
            for (int x = 0; x < kPixels; ++x) {
                if (a.at(x, y)[3] <= 0.01f && b.at(x, y)[3] <= 0.01f) continue;
                diff += std::abs(a.at(x, y)[c] - b.at(x, y)[c]);
                sum += b.at(x, y)[c];
            }
        worst = std::max(worst, diff / sum);
    }
    return worst;
}

render::Image mean(const std::vector<render::Image>& images)
{
    render::Image out = images.front();
    for (size_t i = 1; i < images.size(); ++i)
        for (size_t p = 0; p < out.pixels.size(); ++p) out.pixels[p] += images[i].pixels[p];
    for (float& v : out.pixels) v /= float(images.size());
    return out;
}

std::vector<render::Light> sun()
{
    render::Light l;
    l.direction = Vec3d(-0.3, -0.2, -1.0);
    l.intensity = 3.0;
    return {l};
}

} // namespace

TEST(MotionBlur, ATranslatingSphereBlursAsTheMeanOfItsPositions)
{
    const openvdb::FloatGrid::Ptr fog = sphereFog();
    const Vec3d v(0.8, 0.3, 0.0); // world units per second: 0.8 of the 2.5-unit image across
    std::vector<render::ShutterTime> times;
    std::vector<render::Image> still;
    for (int k = 0; k < kTimes; ++k) {
        times.push_back({timeAt(k), orthoDown(Vec3d(0.0)), sun()});
        openvdb::FloatGrid::Ptr moved = fog->copy(); // the tree shared, the transform moved
        moved->setTransform(fog->transform().copy());
        moved->transform().postTranslate(v * timeAt(k));
        still.push_back(render::renderVolume(*moved, nullptr, orthoDown(Vec3d(0.0)), sun(),
                                             medium(), subFrame(k)));
    }
    const render::Image blurred =
        render::renderMotionBlurred(*fog, nullptr, uniformVelocity(*fog, v).get(), times, medium(),
                                    settings(kTimes * kSamplesPerTime));
    EXPECT_LT(meanRelativeDifference(blurred, mean(still)), 0.01);
    // And it is blurred: the instant differs from it by far more.
    const render::Image instant =
        render::renderVolume(*fog, nullptr, orthoDown(Vec3d(0.0)), sun(), medium(), settings(1));
    EXPECT_GT(meanRelativeDifference(instant, mean(still)), 0.1);
}

TEST(MotionBlur, APanningCameraBlursAStillSphere)
{
    // No velocity; the camera moves 0.6 world units along x over the shutter.
    const openvdb::FloatGrid::Ptr fog = sphereFog();
    std::vector<render::ShutterTime> times;
    std::vector<render::Image> still;
    for (int k = 0; k < kTimes; ++k) {
        const Camera camera = orthoDown(Vec3d(0.6 * timeAt(k), 0.0, 0.0));
        times.push_back({timeAt(k), camera, sun()});
        still.push_back(render::renderVolume(*fog, nullptr, camera, sun(), medium(), subFrame(k)));
    }
    const render::Image blurred =
        render::renderMotionBlurred(*fog, nullptr, uniformVelocity(*fog, Vec3d(0.0)).get(), times,
                                    medium(), settings(kTimes * kSamplesPerTime));
    EXPECT_LT(meanRelativeDifference(blurred, mean(still)), 0.01);
}

TEST(MotionBlur, ATurningBarBlursAsTheMeanOfItsTurns)
{
    // Turning at 0.5 radians per second, 14 degrees each way over the shutter. Eulerian blur reads
    // rho(p - (w x p) s), off the arc by r (w s)^2 / 2: under a voxel at the bar's tips.
    const openvdb::FloatGrid::Ptr fog = barFog();
    const double omega = 0.5;
    std::vector<render::ShutterTime> times;
    std::vector<render::Image> still;
    for (int k = 0; k < kTimes; ++k) {
        times.push_back({timeAt(k), orthoDown(Vec3d(0.0)), sun()});
        openvdb::FloatGrid::Ptr turned = fog->copy();
        turned->setTransform(fog->transform().copy());
        turned->transform().postRotate(omega * timeAt(k), openvdb::math::Z_AXIS);
        still.push_back(render::renderVolume(*turned, nullptr, orthoDown(Vec3d(0.0)), sun(),
                                             medium(), subFrame(k)));
    }
    const render::Image reference = mean(still);
    const render::Image blurred =
        render::renderMotionBlurred(*fog, nullptr, turningVelocity(*fog, omega).get(), times,
                                    medium(), settings(kTimes * kSamplesPerTime));
    EXPECT_LT(meanRelativeDifference(blurred, reference), 0.03);
    const render::Image instant =
        render::renderVolume(*fog, nullptr, orthoDown(Vec3d(0.0)), sun(), medium(), settings(1));
    EXPECT_GT(meanRelativeDifference(instant, reference), 0.1);
}
