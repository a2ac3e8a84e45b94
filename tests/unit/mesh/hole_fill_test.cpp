// Hole filling (mesh/HoleFill.h): patches close every loop with the mesh's orientation and
// continue its surface.
#include "mesh/HoleFill.h" // private to the library; tested directly
#include "mesh/Orientation.h"
#include "support/OpenMeshes.h"
#include "support/VoxelizeChecks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace volmorph;
using namespace volmorph::test;

namespace {

Mesh sphereMesh()
{
    return importMesh(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes" /
                      "sphere.obj");
}

/// The largest |distance from the origin - 0.5| over the points from `first` on.
double worstRadialError(const Mesh& mesh, size_t first)
{
    double worst = 0.0;
    for (size_t i = first; i < mesh.points.size(); ++i)
        worst = std::max(worst, std::abs(Vec3d(mesh.points[i]).length() - 0.5));
    return worst;
}

} // namespace

TEST(HoleFill, ACapComesBackRound)
{
    const Mesh closed = sphereMesh(); // radius 0.5
    Mesh open = withoutTriangles(closed, [](const Vec3d& p) { return p.z() > 0.375; });
    const size_t kept = open.points.size();
    const detail::HoleFillStats stats = detail::fillHoles(open, 0.0);
    EXPECT_EQ(stats.holes, 1u);
    EXPECT_EQ(stats.unclosed, 0u);
    EXPECT_TRUE(open.report.watertight());
    EXPECT_TRUE(open.report.consistentlyOriented());
    EXPECT_EQ(open.report.components, 1u);
    ASSERT_GT(open.points.size(), kept);
    // The cap rises 0.125 above its rim's plane; a flat patch would miss the sphere by that much.
    const double error = worstRadialError(open, kept);
    std::printf("cap patch: worst radial error %.4f (radius 0.5)\n", error);
    EXPECT_LT(error, 0.01);
    EXPECT_NEAR(signedVolume(open) / signedVolume(closed), 1.0, 0.005);
}

TEST(HoleFill, EachOfManyHolesIsClosed)
{
    const Mesh closed = torus(1.0, 0.35, 120, 40);
    Mesh open = withoutTriangles(closed, smallHoles(closed, 12, 0.12, 3));
    const detail::HoleFillStats stats = detail::fillHoles(open, 0.0);
    EXPECT_GE(stats.holes, 10u);
    EXPECT_TRUE(open.report.watertight());
    EXPECT_TRUE(open.report.consistentlyOriented());
    EXPECT_NEAR(signedVolume(open) / signedVolume(closed), 1.0, 0.002);
}

TEST(HoleFill, ColoursAreFairedToo)
{
    Mesh closed = sphereMesh();
    closed.colors.clear();
    for (const Vec3f& p : closed.points) closed.colors.emplace_back(0.5f + p.z(), 0.2f, 0.7f);
    Mesh open = withoutTriangles(closed, [](const Vec3d& p) { return p.z() > 0.375; });
    const size_t kept = open.points.size();
    detail::fillHoles(open, 0.0);
    ASSERT_EQ(open.colors.size(), open.points.size());
    for (size_t i = kept; i < open.points.size(); ++i) {
        EXPECT_NEAR(open.colors[i][1], 0.2f, 1e-4f);
        EXPECT_GT(open.colors[i][0], 0.5f + 0.375f - 0.01f); // above the rim's red, as z is
    }
}

TEST(HoleFill, HolesMeetingAtAVertexArePatchedApart)
{
    // Two triangles around one vertex that share no edge: their removal leaves one boundary walk
    // through that vertex twice (a pinch). Patched as one loop, the patch would reuse the pinch's
    // edges; as two, the mesh closes into a manifold.
    Mesh mesh = sphereMesh();
    std::vector<size_t> around;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if (mesh.triangles[t][k] == 0) around.push_back(t);
    auto shareEdge = [&](size_t a, size_t b) {
        int common = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) common += mesh.triangles[a][i] == mesh.triangles[b][j];
        return common >= 2;
    };
    size_t second = 1;
    while (second < around.size() && shareEdge(around[0], around[second])) ++second;
    ASSERT_LT(second, around.size());
    mesh.triangles.erase(mesh.triangles.begin() +
                         std::ptrdiff_t(std::max(around[0], around[second])));
    mesh.triangles.erase(mesh.triangles.begin() +
                         std::ptrdiff_t(std::min(around[0], around[second])));
    analyzeTopology(mesh);
    ASSERT_EQ(mesh.report.boundaryEdges, 6u);
    const detail::HoleFillStats stats = detail::fillHoles(mesh, 0.0);
    EXPECT_EQ(stats.holes, 2u);
    EXPECT_TRUE(mesh.report.watertight()); // no boundary and no non-manifold edge
    EXPECT_TRUE(mesh.report.consistentlyOriented());
}
