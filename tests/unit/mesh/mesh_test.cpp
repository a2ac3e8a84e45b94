#include <volmorph/Mesh.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace volmorph;

namespace {

const std::filesystem::path kMeshes =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "tests" / "data" / "meshes";

Mesh load(const std::string& name, const ObjectTransform& xf = {})
{
    return importMesh(kMeshes / name, xf);
}

void expectBounds(const Mesh& m, const Vec3d& lo, const Vec3d& hi)
{
    const auto [a, b] = m.bounds();
    EXPECT_NEAR((a - lo).length(), 0.0, 1e-6) << "min " << a;
    EXPECT_NEAR((b - hi).length(), 0.0, 1e-6) << "max " << b;
}

/// The signed volume of a closed mesh (divergence theorem); positive when it faces outward.
double signedVolume(const Mesh& m)
{
    double v = 0.0;
    for (const Vec3I& t : m.triangles) {
        const Vec3d a(m.points[t[0]]), b(m.points[t[1]]), c(m.points[t[2]]);
        v += a.dot(b.cross(c)) / 6.0;
    }
    return v;
}

/// Expects importMesh to refuse `name` with a message containing `fragment`, naming the file.
void expectRefused(const std::string& name, const std::string& fragment)
{
    try {
        load(name);
        ADD_FAILURE() << name << " was accepted";
    } catch (const UserError& e) {
        ASSERT_EQ(e.diagnostics().size(), 1u);
        const Diagnostic& d = e.diagnostics()[0];
        EXPECT_EQ(d.where.file, (kMeshes / name).string());
        EXPECT_NE(d.message.find(fragment), std::string::npos) << d.str();
    }
}

} // namespace

TEST(MeshImport, Obj)
{
    const Mesh m = load("cube.obj");
    EXPECT_EQ(m.points.size(), 8u);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_TRUE(m.report.watertight());
    EXPECT_TRUE(m.report.consistentlyOriented());
    EXPECT_EQ(m.report.components, 1u);
    EXPECT_FALSE(m.hasColors());
    expectBounds(m, Vec3d(-0.5), Vec3d(0.5));
    EXPECT_NEAR(signedVolume(m), 1.0, 1e-6);
}

TEST(MeshImport, ObjQuadsAreTriangulated)
{
    const Mesh m = load("cube_quads.obj");
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_TRUE(m.report.watertight());
    EXPECT_NEAR(std::abs(signedVolume(m)), 1.0, 1e-6);
}

TEST(MeshImport, BinaryStlIsWeldedIntoOneShell)
{
    // STL stores every triangle's corners separately; welding must reconnect them.
    const Mesh m = load("cube_binary.stl");
    EXPECT_EQ(m.points.size(), 8u);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_TRUE(m.report.watertight());
    EXPECT_EQ(m.report.components, 1u);
    EXPECT_NEAR(signedVolume(m), 1.0, 1e-6);
}

TEST(MeshImport, AsciiStl)
{
    const Mesh m = load("tetra_ascii.stl");
    EXPECT_EQ(m.points.size(), 4u);
    EXPECT_EQ(m.triangles.size(), 4u);
    EXPECT_TRUE(m.report.watertight());
    EXPECT_NEAR(signedVolume(m), 1.0 / 6.0, 1e-6);
}

TEST(MeshImport, Off)
{
    const Mesh m = load("tetra.off");
    EXPECT_EQ(m.points.size(), 4u);
    EXPECT_EQ(m.triangles.size(), 4u);
    EXPECT_TRUE(m.report.watertight());
    expectBounds(m, Vec3d(0), Vec3d(1));
}

TEST(MeshImport, PlyVertexColours)
{
    const Mesh m = load("tetra_colors.ply");
    ASSERT_TRUE(m.hasColors());
    ASSERT_EQ(m.colors.size(), m.points.size());
    for (size_t i = 0; i < m.points.size(); ++i) {
        // The fixture colours vertex (0,0,0) red, (1,0,0) green, (0,1,0) blue, (0,0,1) white.
        const Vec3f& p = m.points[i];
        Vec3f expected(1, 1, 1);
        if (p == Vec3f(0, 0, 0))
            expected = Vec3f(1, 0, 0);
        else if (p == Vec3f(1, 0, 0))
            expected = Vec3f(0, 1, 0);
        else if (p == Vec3f(0, 1, 0))
            expected = Vec3f(0, 0, 1);
        EXPECT_NEAR((m.colors[i] - expected).length(), 0.0, 1e-3) << "vertex " << p;
    }
}

TEST(MeshImport, GltfAppliesItsNodeTransform)
{
    const Mesh m = load("tetra.gltf");
    EXPECT_EQ(m.triangles.size(), 4u);
    expectBounds(m, Vec3d(10, 0, 0), Vec3d(11, 1, 1)); // the node translates by (10, 0, 0)
}

TEST(MeshImport, SceneTransformIsApplied)
{
    ObjectTransform xf;
    xf.scale = Vec3d(2.0);
    xf.rotateRadians = Vec3d(0, 0, M_PI / 2);
    xf.translate = Vec3d(0, 0, 5);
    const Mesh m = load("tetra.off", xf);
    // Rotating +90 degrees about z takes +x to +y, so the unit tetrahedron spans x in [-2, 0].
    expectBounds(m, Vec3d(-2, 0, 5), Vec3d(0, 2, 7));
    EXPECT_NEAR(signedVolume(m), 8.0 / 6.0, 1e-5);
}

TEST(MeshTopology, OpenMeshIsReportedNotRefused)
{
    const Mesh m = load("open_cube.obj");
    EXPECT_FALSE(m.report.watertight());
    EXPECT_EQ(m.report.boundaryEdges, 4u);
    EXPECT_EQ(m.report.nonManifoldEdges, 0u);
}

TEST(MeshTopology, InconsistentOrientation)
{
    const Mesh m = load("flipped_cube.obj");
    EXPECT_TRUE(m.report.watertight());
    EXPECT_FALSE(m.report.consistentlyOriented());
    EXPECT_EQ(m.report.misorientedEdges, 3u);
}

TEST(MeshTopology, NonManifoldEdge)
{
    const Mesh m = load("nonmanifold.obj");
    EXPECT_EQ(m.report.nonManifoldEdges, 1u);
    EXPECT_EQ(m.report.boundaryEdges, 6u);
    EXPECT_FALSE(m.report.watertight());
}

TEST(MeshTopology, SeveralShells)
{
    const Mesh m = load("two_cubes.obj");
    EXPECT_EQ(m.report.components, 2u);
    EXPECT_TRUE(m.report.watertight());
    EXPECT_NEAR(signedVolume(m), 2.0, 1e-6);
}

TEST(MeshTopology, DegenerateTrianglesAreDroppedAndCounted)
{
    const Mesh m = load("degenerate.obj");
    EXPECT_EQ(m.report.inputTriangles, 13u);
    EXPECT_EQ(m.report.degenerateTriangles, 1u);
    EXPECT_EQ(m.triangles.size(), 12u);
}

TEST(MeshErrors, BadFilesAreRefusedWithTheirName)
{
    expectRefused("nan.obj", "non-finite coordinate");
    expectRefused("inf.off", "non-finite coordinate");
    expectRefused("empty.obj", "mesh file is empty");
    expectRefused("no_faces.obj", "cannot read mesh");
    expectRefused("all_degenerate.obj", "degenerate");
    expectRefused("garbage.stl", "cannot read mesh");
    expectRefused("truncated.ply", "no triangles"); // the header promises faces the file lacks
    expectRefused("truncated_binary.stl", "cannot read mesh");
    expectRefused("does_not_exist.obj", "not found");
}

TEST(MeshErrors, SceneKeyIsNamedWhenGiven)
{
    const SourceLocation key{"scene.toml", 4, 8};
    try {
        importMesh(kMeshes / "nan.obj", {}, key);
        FAIL();
    } catch (const UserError& e) {
        const Diagnostic& d = e.diagnostics().at(0);
        EXPECT_EQ(d.where.str(), "scene.toml:4:8");
        EXPECT_NE(d.message.find("nan.obj"), std::string::npos) << d.str();
    }
}

TEST(MeshImport, RealMeshesOfTheScenes)
{
    const std::filesystem::path scenes =
        std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";
    const Mesh bunny = importMesh(scenes / "bunny.obj");
    EXPECT_EQ(bunny.points.size(), 1839u);
    EXPECT_EQ(bunny.triangles.size(), 3674u);
    EXPECT_TRUE(bunny.report.watertight());
    const Mesh holes = importMesh(scenes / "elephant-with-holes.off");
    EXPECT_FALSE(holes.report.watertight());
    EXPECT_GT(holes.report.boundaryEdges, 100u);
    const Mesh bones = importMesh(scenes / "bones.off");
    EXPECT_EQ(bones.report.components, 26u);
}
