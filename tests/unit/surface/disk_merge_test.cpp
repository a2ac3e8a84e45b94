// The disk correspondence (surface/DiskMerge.h): two meshes with one boundary loop, differently
// tessellated (a dome of rings, a square bumpy sheet of quads), merged in the plane. Checked
// against the inputs themselves: each side's own vertices kept exactly, every merged vertex on
// both surfaces (1e-9 of the diagonal), the merged mesh's area equal to each input's (it covers
// both whole), its boundary on both boundaries, no triangle facing against the input it lies in.
#include "surface/Correspondence.h"
#include "surface/DiskMerge.h"

#include "support/MergeChecks.h"
#include "support/SurfaceChecks.h"
#include "support/SurfaceShapes.h"

#include <gtest/gtest.h>

#include <map>

namespace volmorph::detail {
namespace {

const SourceLocation kWhere{"scene.toml", 9, 18};

std::vector<Vec3d> pointsOf(const Mesh& m)
{
    return {m.points.begin(), m.points.end()};
}

/// The edges used by one triangle only.
std::vector<std::pair<uint32_t, uint32_t>> boundaryEdges(const std::vector<Vec3I>& tris)
{
    std::map<std::pair<uint32_t, uint32_t>, int> uses;
    for (const Vec3I& t : tris)
        for (int k = 0; k < 3; ++k)
            ++uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
    std::vector<std::pair<uint32_t, uint32_t>> out;
    for (const auto& [e, n] : uses)
        if (n == 1) out.push_back(e);
    return out;
}

/// The distance from `p` to the boundary polyline of `m`.
double distanceToBoundary(const Mesh& m, const Vec3d& p)
{
    double best = 1e300;
    for (const auto& [a, b] : boundaryEdges(m.triangles)) {
        const Vec3d pa(m.points[a]), pb(m.points[b]);
        const double t = std::clamp((p - pa).dot(pb - pa) / (pb - pa).lengthSqr(), 0.0, 1.0);
        best = std::min(best, (pa + t * (pb - pa) - p).length());
    }
    return best;
}

TEST(DiskMerge, ADomeOfRingsAndASheetOfQuadsBoundaryOntoBoundary)
{
    const Mesh a = test::dome(9, 28);
    Mesh sheet = test::bumpySheet(14, 0.4);
    for (Vec3f& p : sheet.points)
        p = Vec3f(1.3f * p.x() + 4.0f, p.y(), p.z()); // elsewhere, stretched
    const Mesh& b = sheet;
    const Corresponded c = diskMerge(a, b, {}, kWhere);
    EXPECT_EQ(c.used, Correspondence::Disk);
    const size_t na = a.points.size(), nb = b.points.size();
    ASSERT_EQ(c.source.size(), na + nb + c.crossings);
    for (size_t i = 0; i < na; ++i) EXPECT_EQ(c.source[i], Vec3d(a.points[i]));
    for (size_t j = 0; j < nb; ++j) EXPECT_EQ(c.target[na + j], Vec3d(b.points[j]));
    const std::vector<std::pair<uint32_t, uint32_t>> rim = boundaryEdges(c.triangles);
    for (const auto& [mesh, merged] : {std::pair{&a, &c.source}, std::pair{&b, &c.target}}) {
        const std::vector<Vec3d> p = pointsOf(*mesh);
        const auto [lo, hi] = mesh->bounds();
        const double diagonal = (hi - lo).length();
        double worst = 0.0, rimWorst = 0.0;
        for (const Vec3d& x : *merged)
            worst = std::max(worst, test::distanceTo(p, mesh->triangles, x));
        EXPECT_LT(worst, 1e-9 * diagonal) << mesh->file;
        EXPECT_NEAR(test::area(*merged, c.triangles) / test::area(p, mesh->triangles), 1.0, 1e-9)
            << mesh->file;
        for (const auto& [u, v] : rim)
            for (uint32_t w : {u, v})
                rimWorst = std::max(rimWorst, distanceToBoundary(*mesh, (*merged)[w]));
        EXPECT_LT(rimWorst, 1e-9 * diagonal) << mesh->file << ": the merged boundary is off it";
        // Every merged triangle with an area faces as the input's surface there does.
        EXPECT_EQ(test::facingAgainst(*merged, c.triangles, p, mesh->triangles, diagonal), 0u)
            << mesh->file;
    }
    std::printf("dome (%zu) and sheet (%zu): %zu merged vertices, %zu crossings\n", na, nb,
                c.source.size(), c.crossings);
}

std::string refusal(const Mesh& a, const Mesh& b, Correspondence correspondence)
{
    SurfaceSpec spec;
    spec.correspondence = correspondence;
    spec.correspondenceWhere = kWhere;
    return test::refusal(a, b, spec);
}

TEST(DiskMerge, RefusesClosedMeshesAndSeveralLoopsNamingTheMesh)
{
    const Mesh sheet = test::bumpySheet(6, 0.2);
    const Mesh ball = test::radialSphere(
        5, 8, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "ball.obj");
    EXPECT_NE(
        refusal(sheet, ball, Correspondence::Disk)
            .find("surface.correspondence = \"disk\": ball.obj has no boundary (a closed mesh); "
                  "the disk map needs one boundary loop"),
        std::string::npos);
    Mesh pipe = test::tube(5, 8, 2.0, 0.3); // without its two end caps: two loops
    pipe.triangles.resize(pipe.triangles.size() - 16);
    analyzeTopology(pipe);
    pipe.file = "pipe.obj";
    const std::string loops = refusal(sheet, pipe, Correspondence::Disk);
    EXPECT_NE(loops.find("pipe.obj: 2 boundary loops"), std::string::npos) << loops;
    // auto on two open meshes: the disk merge.
    EXPECT_EQ(refusal(sheet, test::dome(4, 10), Correspondence::Auto), "");
}

TEST(DiskMerge, LandmarksMeetAndFoldingOnesAreRefused)
{
    const Mesh a = test::dome(9, 28);
    const Mesh b = test::bumpySheet(14, 0.4);
    auto nearest = [](const Mesh& m, const Vec3d& p) {
        const std::vector<Vec3d> pts = pointsOf(m);
        Vec3d best = p;
        for (const Vec3I& t : m.triangles) {
            Vec3d uvw;
            const Vec3d q = openvdb::math::closestPointOnTriangleToPoint(pts[t[0]], pts[t[1]],
                                                                         pts[t[2]], p, uvw);
            if ((q - p).length() < (best - p).length() || best == p) best = q;
        }
        return best;
    };
    // Two points of the dome onto two of the sheet, on the same side of the centre as each other.
    const std::vector<SurfaceLandmark> marks = {
        {Vec3d(0.5, 0.85, 0.1), Vec3d(0.6, 0.2, 0.1), {"scene.toml", 12, 1}},
        {Vec3d(-0.3, 0.9, -0.3), Vec3d(-0.4, 0.3, -0.5), {"scene.toml", 16, 1}}};
    const Corresponded c = diskMerge(a, b, marks, kWhere);
    for (const SurfaceLandmark& l : marks) {
        const Vec3d pa = nearest(a, l.source), pb = nearest(b, l.target);
        double apart = 1e300; // the source's distance where the target's point is
        for (size_t v = 0; v < c.source.size(); ++v)
            if ((c.target[v] - pb).length() < 1e-9)
                apart = std::min(apart, (c.source[v] - pa).length());
        EXPECT_LT(apart, 1e-9) << l.where.str() << " does not meet";
    }
    EXPECT_NEAR(test::area(c.source, c.triangles) / test::area(pointsOf(a), a.triangles), 1.0,
                1e-9);
    EXPECT_NEAR(test::area(c.target, c.triangles) / test::area(pointsOf(b), b.triangles), 1.0,
                1e-9);

    // The same two landmarks with their target points swapped, and a third pinning the middle:
    // the map would have to turn the disk inside out between them.
    const std::vector<SurfaceLandmark> crossed = {
        {Vec3d(0.6, 0.8, 0.0), Vec3d(-0.8, 0.1, 0.0), {"scene.toml", 12, 1}},
        {Vec3d(-0.6, 0.8, 0.0), Vec3d(0.8, 0.1, 0.0), {"scene.toml", 16, 1}},
        {Vec3d(0.0, 1.0, 0.0), Vec3d(0.0, 0.4, 0.0), {"scene.toml", 20, 1}},
        {Vec3d(0.0, 0.8, 0.6), Vec3d(0.0, 0.1, 0.8), {"scene.toml", 24, 1}}};
    try {
        diskMerge(a, b, crossed, kWhere);
        ADD_FAILURE() << "landmarks that fold the disk were accepted";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "scene.toml:12:1: [[pair]]: the landmarks (scene.toml:12:1, "),
                  std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot meet without folding it"), std::string::npos);
    }
}

} // namespace
} // namespace volmorph::detail
