// An in-between exported as a mesh (Export.h): closed, coloured, readable back.
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;

TEST(Morph, InBetweenExportsAsAClosedColouredMesh)
{
    const double voxel = 0.02;
    const VolumeSet s = voxelized("sphere.obj", voxel),
                    d = voxelized("cube.obj", voxel, placed(Vec3d(0.6, 0, 0), 0.8));
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const auto p = pair(FeatureType::Box, element(Vec3d(0.0)),
                        element(Vec3d(0.6, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0.8)));
    const Morpher morpher(s, d, {p}, WarpSpec{}, blend);
    const VolumeSet mid = morpher.frame(0.5);
    const Mesh surface = surfaceMesh(mid);
    EXPECT_TRUE(surface.report.watertight());
    EXPECT_TRUE(surface.report.consistentlyOriented());
    EXPECT_EQ(surface.report.components, 1u);
    double volume = 0.0;
    for (const Vec3I& t : surface.triangles)
        volume += Vec3d(surface.points[t[0]])
                      .dot(Vec3d(surface.points[t[1]]).cross(Vec3d(surface.points[t[2]]))) /
                  6.0;
    EXPECT_NEAR(volume / (moments(*mid.density).mass * std::pow(voxel, 3)), 1.0,
                0.02); // outward, same volume

    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "volmorph_export_test";
    std::filesystem::create_directories(dir);
    writeMesh(surface, dir / "mid.ply");
    const Mesh back = importMesh(dir / "mid.ply");
    EXPECT_EQ(back.triangles.size(), surface.triangles.size());
    EXPECT_TRUE(back.report.watertight());
    ASSERT_TRUE(back.hasColors());
    EXPECT_THROW(writeMesh(surface, dir / "mid.stl"), UserError);
    writeMesh(surface, dir / "mid.obj");
    EXPECT_EQ(importMesh(dir / "mid.obj").triangles.size(), surface.triangles.size());
    size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        files += entry.is_regular_file();
    EXPECT_GE(files, 2u);
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(entry.path().string().find("partial"), std::string::npos) << entry.path();
    std::filesystem::remove_all(dir);
}
