// Meshes with holes keep the interior of their closed originals (Voxelize.h: how inside and outside
// are decided). Each case is measured by the IoU of the two interiors at 256 voxels across.
#include <volmorph/Voxelize.h>

#include "mesh/HoleFill.h" // private to the library; tested directly
#include "mesh/Orientation.h"
#include "mesh/WindingNumber.h"
#include "support/OpenMeshes.h"
#include "support/VoxelizeChecks.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

using namespace volmorph;
using namespace volmorph::test;

namespace {

Mesh sceneMesh(const std::string& name, const ObjectTransform& xf = {})
{
    return importMesh(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes" / name, xf);
}

/// IoU of the interiors of `closed` and `open` voxelized alike, printed under `name`.
double iouAgainstClosed(const char* name, const Mesh& closed, const Mesh& open, double voxelSize,
                        VoxelizeStats* stats = nullptr)
{
    VoxelizeOptions o;
    o.voxelSize = voxelSize;
    const VolumeSet a = voxelize(closed, o);
    const VolumeSet b = voxelize(open, o, nullptr, stats);
    const double iou = insideIoU(*a.density, *b.density);
    std::printf("%s: IoU %.4f against the closed mesh\n", name, iou);
    return iou;
}

/// The sphere of radius 0.5 without its cap above z = 0.375, an eighth of its area.
bool cap(const Vec3d& p)
{
    return p.z() > 0.375;
}

} // namespace

TEST(Voxelize, MeshWithHolesMatchesTheClosedMesh)
{
    // CGAL's elephant-with-holes lacks a fifth of the elephant's triangles. Both share a frame.
    const Mesh closed = sceneMesh("elephant.off");
    const Mesh holes = sceneMesh("elephant-with-holes.off");
    ASSERT_FALSE(holes.report.watertight());
    // 256 voxels across the elephant's longest side (1 world unit).
    EXPECT_GE(iouAgainstClosed("elephant-with-holes", closed, holes, 1.0 / 256), 0.98);
}

TEST(Voxelize, TorusCutAlongAnArcKeepsItsTube)
{
    const Mesh closed = torus(1.0, 0.35, 240, 80);
    const auto cut = [](const Vec3d& p) { return outerArc(p, 1.0); };
    EXPECT_NEAR(areaFraction(closed, cut), 0.10, 0.005);
    const Mesh open = withoutTriangles(closed, cut);
    ASSERT_EQ(open.report.boundaryEdges > 0, true);
    EXPECT_GE(iouAgainstClosed("torus cut along an arc", closed, open, 2.7 / 256), 0.97);
}

TEST(Voxelize, SphereWithoutACapKeepsIt)
{
    const Mesh closed = sceneMesh("sphere.obj");
    EXPECT_NEAR(areaFraction(closed, cap), 0.125, 0.005);
    const Mesh open = withoutTriangles(closed, cap);
    EXPECT_GE(iouAgainstClosed("sphere without a cap", closed, open, 1.0 / 256), 0.97);
}

TEST(Voxelize, ManySmallHolesChangeNothing)
{
    const Mesh closed = sceneMesh("bunny.obj");
    const auto [lo, hi] = closed.bounds();
    const double size = (hi - lo).length();
    const Mesh open = withoutTriangles(closed, smallHoles(closed, 60, 0.025 * size, 11));
    ASSERT_GT(open.report.boundaryEdges, 300u);
    VoxelizeStats stats;
    const double voxel = std::max({hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()}) / 256;
    EXPECT_GE(iouAgainstClosed("bunny with 60 small holes", closed, open, voxel, &stats), 0.99);
}

TEST(Voxelize, HoleAndNestedShell)
{
    // A cut sphere around a cavity (an inward-facing inner sphere of half its radius).
    ObjectTransform half;
    half.scale = Vec3d(0.5);
    const Mesh inner = sceneMesh("sphere.obj", half);
    Mesh closed = sceneMesh("sphere.obj");
    Mesh open = withoutTriangles(closed, cap);
    append(closed, inner, /*flip=*/true);
    append(open, inner, /*flip=*/true);
    ASSERT_EQ(open.report.components, 2u);
    EXPECT_GE(iouAgainstClosed("sphere without a cap, around a cavity", closed, open, 1.0 / 256),
              0.97);
}

TEST(Voxelize, WindingSignAgreesWithTheWindingNumberAtEveryVoxel)
{
    // The winding-number path evaluates w only where the sign can change; brute force evaluates
    // it at every voxel of the box around the band, on the mesh the path signs (repaired, filled).
    const Mesh holes = sceneMesh("elephant-with-holes.off");
    VoxelizeOptions o;
    o.voxelSize = 1.0 / 64;
    o.sign = VoxelizeOptions::Sign::WindingNumber;
    VoxelizeStats stats;
    const VolumeSet v = voxelize(holes, o, nullptr, &stats);
    ASSERT_EQ(stats.signPath, VoxelizeStats::SignPath::WindingNumber);
    Mesh filled = holes;
    detail::repairOrientation(filled);
    detail::fillHoles(filled, *o.voxelSize);
    const detail::WindingNumber winding(filled.points, filled.triangles);
    openvdb::CoordBBox box = v.sdf->evalActiveVoxelBoundingBox();
    box.expand(12);
    size_t voxels = 0, disagree = 0;
    for (auto ijk = box.begin(); ijk; ++ijk, ++voxels) {
        const bool inside = winding(v.sdf->indexToWorld(*ijk)) > 0.5;
        if (inside != (v.sdf->tree().getValue(*ijk) < 0.0f)) ++disagree;
    }
    std::printf("%zu of %zu voxels disagree with w\n", disagree, voxels);
    EXPECT_EQ(disagree, 0u);
}

TEST(Voxelize, MeshOpenAfterFillingTakesTheWindingNumber)
{
    // A fin (a triangle on one of the rim's edges, and so a non-manifold edge once the hole is
    // closed) keeps the mesh open after filling.
    const Mesh closed = sceneMesh("sphere.obj");
    Mesh open = withoutTriangles(closed, cap);
    const Vec3I rim = open.triangles[0];
    open.points.push_back(Vec3f(0.0f, 0.0f, 0.9f));
    open.triangles.emplace_back(rim[1], rim[0], uint32_t(open.points.size() - 1));
    analyzeTopology(open);
    VoxelizeStats stats;
    EXPECT_GE(iouAgainstClosed("sphere without a cap, with a fin", closed, open, 1.0 / 128, &stats),
              0.99);
    EXPECT_EQ(stats.signPath, VoxelizeStats::SignPath::WindingNumber);
    EXPECT_EQ(stats.holesFilled, 1u);
}
