// The sdf blend: end surfaces reproduced, closed forms of concentric spheres, genus change, smooth
// volume change, dust removal.
#include "support/WarpFixtures.h"

#include <volmorph/SceneVolumes.h>

using namespace volmorph;
using namespace volmorph::test;

namespace {

/// The largest displacement between the zero sets of two level sets, in voxels, measured on the
/// grid near either surface (|a| or |b| < half a voxel). With unit gradients the displacement of
/// the zero set there is |a - b| (|b| alone would add up to the half voxel of the sample's offset).
double surfaceDistanceVoxels(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
{
    const double voxel = a.voxelSize()[0];
    double worst = 0.0;
    auto one = [&](const openvdb::FloatGrid& x, const openvdb::FloatGrid& y) {
        auto ya = y.getConstAccessor();
        for (auto it = x.cbeginValueOn(); it; ++it)
            if (std::abs(*it) < 0.5 * voxel)
                worst = std::max(worst, std::abs(double(ya.getValue(it.getCoord())) - double(*it)) /
                                            voxel);
    };
    one(a, b);
    one(b, a);
    return worst;
}

} // namespace

TEST(Morph, SdfModeReproducesTheEndSurfaces)
{
    const Scene scene =
        loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
    ASSERT_EQ(scene.blend.mode, BlendMode::Sdf);
    const double voxel = 0.016;
    const auto [s, d] = defaultSceneObjects(voxel);
    const Morpher morpher(s, d, scene.pairs, scene.warp, scene.blend);
    const VolumeSet first = morpher.frame(0.0), last = morpher.frame(1.0);
    ASSERT_TRUE(first.sdf && last.sdf);
    EXPECT_EQ(first.sdf->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_LE(surfaceDistanceVoxels(*first.sdf, *s.sdf), 1.0);
    EXPECT_LE(surfaceDistanceVoxels(*last.sdf, *d.sdf), 1.0);
    // In between there is one surface: the fog comes from the blended level set alone.
    const VolumeSet mid = morpher.frame(0.5);
    EXPECT_LT(maxDifference(*mid.density, *fogFromLevelSet(*mid.sdf, 1.5f * float(voxel))), 1e-6);
}

namespace {

/// Euler characteristic V - E + F of a closed triangle mesh: 2 - 2 genus per shell.
long eulerCharacteristic(const Mesh& mesh)
{
    std::set<std::pair<uint32_t, uint32_t>> edges;
    for (const Vec3I& t : mesh.triangles)
        for (int i = 0; i < 3; ++i) {
            const uint32_t a = t[i], b = t[(i + 1) % 3];
            edges.insert({std::min(a, b), std::max(a, b)});
        }
    return long(mesh.points.size()) - long(edges.size()) + long(mesh.triangles.size());
}

} // namespace

// Closed form: with exact distances and the identity warp, blending the sdf of concentric spheres
// of radii r0 and r1 gives (1 - t)(|p| - r0) + t(|p| - r1) = |p| - ((1 - t) r0 + t r1): a sphere
// whose radius moves linearly. Distances clamped to a narrow band would instead flip the whole
// shell between the two surfaces at t = 1/2.
TEST(Morph, SdfModeShrinksConcentricSpheresLinearly)
{
    const double voxel = 0.01;
    const VolumeSet big = voxelized("sphere.obj", voxel),
                    small = voxelized("sphere.obj", voxel, placed(Vec3d(0.0), 0.5));
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const Morpher morpher(big, small, {}, WarpSpec{}, blend);
    const double r0 = equivalentRadius(*morpher.frame(0.0).density);
    const double r1 = equivalentRadius(*morpher.frame(1.0).density);
    EXPECT_NEAR(r0, 2.0 * r1, 2.0 * voxel);
    for (double t : {0.2, 0.4, 0.5, 0.6, 0.8}) {
        const VolumeSet frame = morpher.frame(t);
        const double expected = (1.0 - t) * r0 + t * r1;
        EXPECT_NEAR(equivalentRadius(*frame.density), expected, 0.5 * voxel) << "t = " << t;
        // The rebuilt band holds distances (closed form: |p| - r) all across it.
        double worst = 0.0;
        for (auto it = frame.sdf->cbeginValueOn(); it; ++it)
            worst = std::max(
                worst, std::abs(double(*it) -
                                (frame.sdf->indexToWorld(it.getCoord()).length() - expected)));
        EXPECT_LE(worst / voxel, 0.5) << "t = " << t; // measured: 0.24 to 0.36
    }
}

// A genus change (sphere, genus 0, into the knot, genus 1) in sdf mode: at every frame the
// in-between is one closed, consistently oriented surface.
TEST(Morph, SdfModeChangesGenusWithOneClosedSurfacePerFrame)
{
    const double voxel = 0.02;
    const VolumeSet sphere = voxelized("sphere.obj", voxel), knot = voxelized("knot1.off", voxel);
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const Morpher morpher(sphere, knot, {}, WarpSpec{}, blend);
    for (int f = 0; f <= 12; ++f) {
        const Mesh surface = surfaceMesh(morpher.frame(f / 12.0));
        ASSERT_FALSE(surface.triangles.empty()) << "frame " << f;
        EXPECT_TRUE(surface.report.watertight()) << "frame " << f;
        EXPECT_TRUE(surface.report.consistentlyOriented()) << "frame " << f;
        EXPECT_EQ(surface.report.components, 1u) << "frame " << f;
        if (f == 0) {
            EXPECT_EQ(eulerCharacteristic(surface), 2) << "the sphere has genus 0";
        }
        if (f == 12) {
            EXPECT_EQ(eulerCharacteristic(surface), 0) << "the knot has genus 1";
        }
    }
}

// The default scene's in-betweens are one closed surface each and change their enclosed volume
// smoothly. Bound: no step between
// consecutive frames exceeds 3 times the mean step |V(last) - V(first)| / (frames - 1). The blended
// surface moves at a speed that varies with the local distance between the two surfaces (measured:
// at most 1.9 times the mean at this resolution); a snap moves a large part of the volume in one
// frame (the narrow-band blend did: about half the total change at t = 1/2, some 11 times the
// mean).
TEST(Morph, SdfModeDefaultSceneIsOneSurfaceChangingSmoothly)
{
    Scene scene =
        loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
    scene.volume.voxelSize = 0.012; // coarser than the scene's 0.008, to keep the test short
    const SceneVolumes volumes = voxelizeScene(scene);
    const Morpher morpher(volumes.source, volumes.target, scene.pairs, scene.warp, scene.blend);
    std::vector<double> v;
    for (int f = scene.frames.first; f <= scene.frames.last; ++f) {
        const VolumeSet frame = morpher.frame(scene.frames.t(f));
        v.push_back(moments(*frame.density).mass * std::pow(frame.density->voxelSize()[0], 3));
        const Mesh surface = surfaceMesh(frame);
        EXPECT_TRUE(surface.report.watertight()) << "frame " << f;
        EXPECT_EQ(surface.report.components, 1u) << "frame " << f;
    }
    const double mean = std::abs(v.back() - v.front()) / double(v.size() - 1);
    ASSERT_GT(mean, 0.0);
    double worst = 0.0;
    for (size_t i = 0; i + 1 < v.size(); ++i)
        worst = std::max(worst, std::abs(v[i + 1] - v[i]) / mean);
    std::printf("largest volume step: %.2f times the mean\n", worst);
    for (size_t i = 0; i + 1 < v.size(); ++i)
        EXPECT_LE(std::abs(v[i + 1] - v[i]), 3.0 * mean)
            << "between frames " << scene.frames.first + int(i) << " and "
            << scene.frames.first + int(i) + 1;
}

// Dust removal (blend.min_island) in sdf mode, on a shape built by OpenVDB's own level-set tools:
// a ball of radius 0.3 with a cavity of radius 1.5 voxels at its centre, and apart from it a speck
// of radius 1.5 voxels (19 voxel centres inside each, fewer than the default 27). With identical
// sides the blend is the shape itself: the speck must go and the cavity be filled; with
// min_island 0 both stay.
TEST(Morph, SdfModeDropsSpecksAndFillsBubbles)
{
    namespace tools = openvdb::tools;
    const float voxel = 0.01f, width = 3.0f;
    auto sphere = [&](float radius, const openvdb::Vec3f& centre) {
        return tools::createLevelSetSphere<openvdb::FloatGrid>(radius, centre, voxel, width);
    };
    openvdb::FloatGrid::Ptr shape = sphere(0.3f, openvdb::Vec3f(0.0f));
    tools::csgDifference(*shape, *sphere(1.5f * voxel, openvdb::Vec3f(0.0f)));
    tools::csgUnion(*shape, *sphere(1.5f * voxel, openvdb::Vec3f(0.5f, 0.0f, 0.0f)));
    VolumeSet side;
    side.sdf = shape;
    side.density = fogFromLevelSet(*shape, 1.5f * voxel);
    side.color = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.5f));
    side.color->setTransform(shape->transform().copy());
    const openvdb::Coord speck(50, 0, 0), cavity(0, 0, 0);
    ASSERT_LT(shape->tree().getValue(speck), 0.0f);
    ASSERT_GT(shape->tree().getValue(cavity), 0.0f);

    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    ASSERT_EQ(blend.minIslandVoxels, 27);
    const VolumeSet cleaned = Morpher(side, side, {}, WarpSpec{}, blend).frame(0.5);
    EXPECT_GT(cleaned.sdf->tree().getValue(speck), 0.0f) << "the speck is dust";
    EXPECT_LT(cleaned.sdf->tree().getValue(cavity), 0.0f) << "the cavity is a bubble";
    EXPECT_EQ(surfaceMesh(cleaned).report.components, 1u);

    blend.minIslandVoxels = 0;
    const VolumeSet kept = Morpher(side, side, {}, WarpSpec{}, blend).frame(0.5);
    EXPECT_LT(kept.sdf->tree().getValue(speck), 0.0f);
    EXPECT_GT(kept.sdf->tree().getValue(cavity), 0.0f);
    EXPECT_EQ(surfaceMesh(kept).report.components, 3u);
}

TEST(Morph, SdfModeWithoutSdfGridsIsRefused)
{
    const double voxel = 0.05;
    VolumeSet s = voxelized("sphere.obj", voxel), d = s;
    d.sdf.reset();
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    EXPECT_THROW(Morpher(s, d, {}, WarpSpec(), blend), std::invalid_argument);
    blend.mode = BlendMode::Density; // density mode reads no sdf
    EXPECT_NO_THROW(Morpher(s, d, {}, WarpSpec(), blend));
}
