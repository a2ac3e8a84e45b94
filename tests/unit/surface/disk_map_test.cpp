// The harmonic disk map (surface/DiskMap.h): one boundary loop onto the unit circle by arc length,
// the interior where the cotangent springs balance, no fold; refusals naming the mesh.
#include "surface/DiskMap.h"

#include "support/SurfaceShapes.h"

#include <gtest/gtest.h>

#include <cmath>

namespace volmorph::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::dome;

const SourceLocation kWhere{"scene.toml", 4, 1};

TEST(DiskMap, HemisphereMapsOntoTheDiskWithoutFolds)
{
    const Mesh dome = test::dome(12, 32);
    const DiskMap map = harmonicDiskMap(dome, kWhere);
    EXPECT_FALSE(map.meanValue);
    ASSERT_EQ(map.boundary.size(), 32u);
    EXPECT_EQ(foldedTriangles(dome, map.uv), 0u);
    std::vector<bool> onBoundary(dome.points.size(), false);
    for (uint32_t b : map.boundary) {
        onBoundary[b] = true;
        EXPECT_NEAR(map.uv[b].norm(), 1.0, 1e-12);
    }
    for (size_t v = 0; v < dome.points.size(); ++v) {
        if (!onBoundary[v]) {
            EXPECT_LT(map.uv[v].norm(), 1.0) << v;
        }
    }
    // The pole maps to the centre (the dome is symmetric about its axis).
    EXPECT_LT(map.uv[0].norm(), 1e-9);
}

TEST(DiskMap, BoundaryIsSpacedByArcLength)
{
    // A flat square of 4 x 4 cells; its boundary is 16 unit edges, so each boundary step is 1/16
    // turn.
    Mesh sheet;
    for (int j = 0; j <= 4; ++j)
        for (int i = 0; i <= 4; ++i) sheet.points.emplace_back(float(i), 0.0f, float(j));
    auto v = [](int i, int j) { return uint32_t(j * 5 + i); };
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            sheet.triangles.emplace_back(v(i, j), v(i, j + 1), v(i + 1, j + 1));
            sheet.triangles.emplace_back(v(i, j), v(i + 1, j + 1), v(i + 1, j));
        }
    // Stretch one side: the boundary's arc lengths become unequal.
    for (Vec3f& p : sheet.points) p.x() = p.x() * p.x();
    const DiskMap map = harmonicDiskMap(sheet, kWhere);
    EXPECT_EQ(foldedTriangles(sheet, map.uv), 0u);
    const auto& b = map.boundary;
    double total = 0.0;
    for (size_t k = 0; k < b.size(); ++k)
        total += (Vec3d(sheet.points[b[(k + 1) % b.size()]]) - Vec3d(sheet.points[b[k]])).length();
    for (size_t k = 0; k < b.size(); ++k) {
        const double edge =
            (Vec3d(sheet.points[b[(k + 1) % b.size()]]) - Vec3d(sheet.points[b[k]])).length();
        const double chord = (map.uv[b[(k + 1) % b.size()]] - map.uv[b[k]]).norm();
        EXPECT_NEAR(chord, 2.0 * std::sin(kPi * edge / total), 1e-12) << k;
    }
}

TEST(DiskMap, RefusesClosedMeshesSeveralLoopsAndPieces)
{
    auto message = [](const Mesh& m) {
        try {
            harmonicDiskMap(m, kWhere);
        } catch (const UserError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    // An open tube: one piece, two loops.
    Mesh tube;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 8; ++k)
            tube.points.emplace_back(float(std::cos(kPi * k / 4)), float(i),
                                     float(std::sin(kPi * k / 4)));
    for (int i = 0; i < 2; ++i)
        for (int k = 0; k < 8; ++k) {
            const uint32_t a = uint32_t(i * 8 + k), b = uint32_t(i * 8 + (k + 1) % 8);
            tube.triangles.emplace_back(a, b + 8, b);
            tube.triangles.emplace_back(a, a + 8, b + 8);
        }
    tube.file = "tube.obj";
    EXPECT_NE(message(tube).find("tube.obj: 2 boundary loops"), std::string::npos) << message(tube);

    const Mesh other = dome(6, 8);
    Mesh twoPieces = dome(6, 8);
    const uint32_t m = uint32_t(twoPieces.points.size());
    for (const Vec3f& p : other.points) twoPieces.points.emplace_back(p + Vec3f(3.0f, 0.0f, 0.0f));
    for (const Vec3I& t : other.triangles)
        twoPieces.triangles.emplace_back(t[0] + m, t[1] + m, t[2] + m);
    const std::string pieces = message(twoPieces);
    EXPECT_NE(pieces.find("scene.toml:4:1"), std::string::npos) << pieces;
    EXPECT_NE(pieces.find("dome.obj: 2 pieces"), std::string::npos) << pieces;

    // A closed octahedron.
    Mesh octa;
    for (const Vec3f& p : {Vec3f(1, 0, 0), Vec3f(-1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, -1, 0),
                           Vec3f(0, 0, 1), Vec3f(0, 0, -1)})
        octa.points.push_back(p);
    for (const Vec3I& t : {Vec3I(0, 2, 4), Vec3I(2, 1, 4), Vec3I(1, 3, 4), Vec3I(3, 0, 4),
                           Vec3I(2, 0, 5), Vec3I(1, 2, 5), Vec3I(3, 1, 5), Vec3I(0, 3, 5)})
        octa.triangles.push_back(t);
    octa.file = "octa.obj";
    EXPECT_NE(message(octa).find("octa.obj: no boundary (a closed mesh)"), std::string::npos)
        << message(octa);
}

TEST(DiskMap, FoldedTrianglesAreCounted)
{
    Mesh tri;
    tri.points = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
    tri.triangles = {Vec3I(0, 1, 2)};
    EXPECT_EQ(foldedTriangles(tri, {{0, 0}, {1, 0}, {0, 1}}), 0u);
    EXPECT_EQ(foldedTriangles(tri, {{0, 0}, {0, 1}, {1, 0}}), 1u);
    EXPECT_EQ(foldedTriangles(tri, {{0, 0}, {1, 0}, {2, 0}}), 1u); // no area
}

} // namespace
} // namespace volmorph::detail
