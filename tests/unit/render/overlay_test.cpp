// Preview drawing: feature outlines, projection, clipped segments, contact sheets.
#include <volmorph/Feature.h>
#include <volmorph/render/Overlay.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace volmorph;
using render::Camera;

namespace {

render::Image blank(int w, int h)
{
    render::Image image;
    image.width = w;
    image.height = h;
    image.pixels.assign(size_t(w) * size_t(h) * 4, 0.0f);
    return image;
}

size_t paintedPixels(const render::Image& image)
{
    size_t n = 0;
    for (size_t p = 3; p < image.pixels.size(); p += 4) n += image.pixels[p] > 0.0f;
    return n;
}

// Orthographic, 2 world units across 200 pixels, looking down -z at the origin: world (x, y) is
// pixel (100 + 100 x, 50 - 100 y).
Camera orthoCamera()
{
    return Camera(Camera::Projection::Orthographic, Vec3d(0, 0, 5), Vec3d(0, 0, 0), Vec3d(0, 1, 0),
                  40.0, 2.0, 200, 100);
}

} // namespace

TEST(Overlay, BoxOutlineHasTwelveEdgesOnItsCorners)
{
    FeatureElement e;
    e.origin = Vec3d(1, 2, 3);
    e.xAxis = Vec3d(0, 1, 0);
    e.yAxis = Vec3d(-1, 0, 0);
    e.zAxis = Vec3d(0, 0, 1);
    e.scale = Vec3d(2, 4, 6);
    const Feature box = Feature::fromElement(e, FeatureType::Box);
    const auto edges = box.outline();
    ASSERT_EQ(edges.size(), 12u);
    int perAxis[3] = {0, 0, 0};
    for (const auto& [a, b] : edges) {
        for (const Vec3d& p : {a, b}) { // every end is a corner: |local u| = 1/2 on each axis
            const Vec3d u = box.toLocal(p);
            for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::abs(u[i]), 0.5, 1e-12);
        }
        const Vec3d d = box.toLocal(b) - box.toLocal(a); // one unit along one local axis
        int axis = -1;
        for (int i = 0; i < 3; ++i)
            if (std::abs(d[i]) > 0.5) axis = i;
        ASSERT_GE(axis, 0);
        EXPECT_NEAR(d.length(), 1.0, 1e-12);
        EXPECT_NEAR((b - a).length(), e.scale[axis], 1e-12);
        ++perAxis[axis];
    }
    EXPECT_EQ(perAxis[0], 4);
    EXPECT_EQ(perAxis[1], 4);
    EXPECT_EQ(perAxis[2], 4);
    EXPECT_EQ(Feature::fromElement(e, FeatureType::Rectangle).outline().size(), 4u);
    EXPECT_EQ(Feature::fromElement(e, FeatureType::Segment).outline().size(), 1u);
    EXPECT_TRUE(Feature::fromElement(e, FeatureType::Point).outline().empty());
}

TEST(Overlay, ProjectionMatchesTheCameraRays)
{
    const Camera camera = orthoCamera();
    const auto q = render::project(camera, Vec3d(0.5, 0.25, 0.0));
    ASSERT_TRUE(q);
    EXPECT_NEAR((*q)[0], 150.0, 1e-9);
    EXPECT_NEAR((*q)[1], 25.0, 1e-9);
    // Perspective: a point on the ray through a pixel projects back to that pixel; behind: nothing.
    const Camera persp(Camera::Projection::Perspective, Vec3d(1, 2, 5), Vec3d(0, 0, 0),
                       Vec3d(0, 1, 0), 50.0, 2.0, 320, 180);
    const render::Ray ray = persp.ray(40.5, 130.25);
    const auto p = render::project(persp, ray.origin + ray.direction * 3.7);
    ASSERT_TRUE(p);
    EXPECT_NEAR((*p)[0], 40.5, 1e-6);
    EXPECT_NEAR((*p)[1], 130.25, 1e-6);
    EXPECT_FALSE(render::project(persp, ray.origin - ray.direction * 1.0));
}

TEST(Overlay, SegmentsAreDrawnWhereTheyProjectAndClipped)
{
    const Camera camera = orthoCamera();
    render::Image image = blank(200, 100);
    render::drawSegment(image, camera, Vec3d(-0.5, 0, 0), Vec3d(0.5, 0, 0), {1, 0, 0}, 1);
    // Pixels 50..150 of row 50, nothing far from it.
    EXPECT_EQ(image.at(100, 50)[0], 1.0f);
    EXPECT_EQ(image.at(100, 50)[3], 1.0f);
    EXPECT_EQ(image.at(60, 50)[0], 1.0f);
    EXPECT_EQ(image.at(100, 60)[3], 0.0f);
    EXPECT_EQ(image.at(170, 50)[3], 0.0f);
    EXPECT_NEAR(double(paintedPixels(image)), 101.0, 1.0);

    // A line reaching far off screen is clipped to the image: exactly one full row, the one y = 0.2
    // projects to, and nothing out of bounds. (Unclipped, it would step through 1e9 pixels: CTest's
    // timeout, not a clock here, is what catches that.)
    render::Image wide = blank(200, 100);
    render::drawSegment(wide, camera, Vec3d(-1e7, 0.2, 0), Vec3d(1e7, 0.2, 0), {0, 1, 0}, 1);
    EXPECT_EQ(paintedPixels(wide), 200u);
    const auto row = render::project(camera, Vec3d(0, 0.2, 0));
    ASSERT_TRUE(row.has_value());
    const int y = int(std::lround((*row)[1]));
    for (int x = 0; x < 200; ++x) EXPECT_EQ(wide.at(x, y)[1], 1.0f) << "x " << x;

    // Perspective: a segment crossing the camera plane keeps only its part in front of the camera.
    const Camera persp(Camera::Projection::Perspective, Vec3d(0, 0, 5), Vec3d(0, 0, 0),
                       Vec3d(0, 1, 0), 60.0, 2.0, 200, 100);
    render::Image cut = blank(200, 100);
    render::drawSegment(cut, persp, Vec3d(0.2, -0.2, 0), Vec3d(0.2, -0.2, 10), {0, 0, 1}, 1);
    EXPECT_GT(paintedPixels(cut), 10u);
    const auto near = render::project(persp, Vec3d(0.2, -0.2, 0));
    EXPECT_EQ(cut.at(int(std::lround((*near)[0])), int(std::lround((*near)[1])))[2], 1.0f);
    render::Image behind = blank(200, 100);
    render::drawSegment(behind, persp, Vec3d(0, 0, 6), Vec3d(1, 1, 9), {0, 0, 1}, 1);
    EXPECT_EQ(paintedPixels(behind), 0u);
}

TEST(Overlay, ContactSheetLaysOutTiles)
{
    std::vector<render::Image> tiles(5, blank(64, 32));
    tiles[4].at(10, 10)[0] = 1.0f; // premultiplied red in the last tile
    tiles[4].at(10, 10)[3] = 1.0f;
    const render::Image sheet =
        render::contactSheet(tiles, {"a", "b", "c", "d", "e"}, 3, 128, {0.1f, 0.1f, 0.1f});
    // 3 columns, 2 rows; tiles scaled to 128 x 64 with 6-pixel gaps and a 22-pixel label band.
    EXPECT_EQ(sheet.width, 3 * (128 + 6) + 6);
    EXPECT_EQ(sheet.height, 2 * (64 + 22 + 6) + 6);
    for (size_t p = 3; p < sheet.pixels.size(); p += 4)
        ASSERT_NEAR(sheet.pixels[p], 1.0f, 1e-5f); // opaque
    EXPECT_NEAR(sheet.at(2, 2)[1], 0.1f, 1e-6f);   // background
    // The red pixel of tile 5 (row 1, column 1) lands near (6 + 134 + 20, 6 + 92 + 20).
    float red = 0.0f;
    for (int y = 112; y < 126; ++y)
        for (int x = 154; x < 168; ++x) red = std::max(red, sheet.at(x, y)[0] - sheet.at(x, y)[1]);
    EXPECT_GT(red, 0.1f);
}
