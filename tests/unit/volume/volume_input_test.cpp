// Volume inputs (VolumeInput.h): grids picked and carried, resampled onto the scene's voxels (a
// rotated, finer copy of the test data generator's cloud gives the same cloud), level sets rebuilt,
// a fog's derived level set, the object's placement; and morphs of a volume into a mesh.
#include "support/VolumeFixtures.h"

#include <volmorph/core/VdbRead.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/VolumeInput.h>

#include <openvdb/tools/LevelSetSphere.h>
#include <tbb/global_control.h>

#include <unistd.h>

using namespace volmorph;
using namespace volmorph::test;
using volmorph::test::cloud::clouds;

namespace {

namespace fs = std::filesystem;

VolumeSource volumeSpec(const fs::path& file)
{
    VolumeSource spec;
    spec.file = file;
    return spec;
}

VolumeSet resampled(const VolumeSource& spec, double voxel, bool needSdf = false)
{
    VolumeInputOptions o;
    o.voxelSize = voxel;
    o.needSdf = needSdf;
    return VolumeInput(spec).resample(o);
}

} // namespace

TEST(VolumeInput, PicksTheDefaultNamesAndCarriesTheOtherGrids)
{
    const VolumeFileInfo info = inspectVolume(volumeSpec(clouds().plain));
    EXPECT_EQ(info.density, "density");
    EXPECT_EQ(info.sdf, "");
    EXPECT_EQ(info.color, "");
    EXPECT_EQ(info.extras, std::vector<std::string>{"temperature"});
    EXPECT_NEAR(info.voxelSize, 0.04, 1e-12);
    // The active bounds lie in the generator's box, half a voxel beyond at most.
    for (int i = 0; i < 3; ++i) {
        EXPECT_GE(info.worldMin[i], cloud::kBounds.min()[i] - 0.02);
        EXPECT_LE(info.worldMax[i], cloud::kBounds.max()[i] + 0.02);
    }
}

TEST(VolumeInput, OnItsOwnVoxelSizeTheGridsAreKeptExactly)
{
    const VolumeSource spec = volumeSpec(clouds().plain);
    const VolumeSet v = resampled(spec, 0.04);
    const auto original =
        openvdb::gridPtrCast<openvdb::FloatGrid>((*readVdbGrids(clouds().plain))[0]);
    EXPECT_EQ(maxDifference(*v.density, *original), 0.0);
    EXPECT_EQ(v.density->activeVoxelCount(), original->activeVoxelCount());
    ASSERT_EQ(v.extras.count("temperature"), 1u);
    EXPECT_EQ(v.extras.at("temperature")->activeVoxelCount(), original->activeVoxelCount());
    EXPECT_FALSE(v.sdf);                           // density mode: no level set derived
    EXPECT_EQ(v.color->background(), Vec3f(0.8f)); // grey, no colour grid
    EXPECT_EQ(v.color->activeVoxelCount(), 0u);
}

TEST(VolumeInput, ARotatedFinerCopyResamplesToTheSameCloud)
{
    // The same world cloud sampled on another lattice, resampled trilinearly onto the first: the
    // difference is the interpolation error of the noise the cloud is made of. Its mass and
    // centroid are the cloud's (the analytic cloud's, sampled on the 0.04 lattice).
    const VolumeSet a = resampled(volumeSpec(clouds().plain), 0.04);
    const VolumeSet b = resampled(volumeSpec(clouds().rotated), 0.04);
    const Moments ma = moments(*a.density), mb = moments(*b.density);
    // Measured 1.0006 and 0.009 voxels; the pointwise difference 0.049 is the trilinear error of
    // the cloud's finest noise, whose wavelength is about two voxels of the 0.03 lattice.
    EXPECT_NEAR(mb.mass / ma.mass, 1.0, 0.005);
    EXPECT_NEAR((mb.centroid - ma.centroid).length(), 0.0, 0.05 * 0.04);
    EXPECT_LT(relativeL1(*a.density, *b.density), 0.08);
    // The temperature (1 - y, linear) resamples exactly where every corner is inside the cloud.
    const auto& t = static_cast<const openvdb::FloatGrid&>(*b.extras.at("temperature"));
    int checked = 0;
    for (auto it = t.cbeginValueOn(); it; ++it) {
        if (!(b.density->tree().getValue(it.getCoord()) > 0.9f)) continue;
        EXPECT_NEAR(*it, 1.0 - t.indexToWorld(it.getCoord()).y(), 1e-4);
        ++checked;
    }
    EXPECT_GT(checked, 200);
}

/// The level set's values against the distance to the sphere of radius 0.5 at the origin: within
/// a third of a voxel near the surface (1.5 voxels), half a voxel to the band's edge (the rebuilt
/// band's outer voxels are a little less exact, as a mesh's are).
void expectSphereDistances(const openvdb::FloatGrid& sdf, double voxel)
{
    int near = 0;
    for (auto it = sdf.cbeginValueOn(); it; ++it) {
        const double d = sdf.indexToWorld(it.getCoord()).length() - 0.5;
        const bool close = std::abs(d) < 1.5 * voxel;
        EXPECT_NEAR(*it, d, (close ? 0.33 : 0.5) * voxel);
        near += close;
    }
    EXPECT_GT(near, 1000);
}

TEST(VolumeInput, ALevelSetIsRebuiltOnTheScenesVoxelsAndGetsItsFog)
{
    const fs::path file = clouds().dir / "ball.vdb";
    openvdb::FloatGrid::Ptr ball =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.5f, openvdb::Vec3f(0.0f), 0.02f);
    ball->setName("surface");
    openvdb::io::File(file.string()).write({ball});
    const VolumeSet v = resampled(volumeSpec(file), 0.03);
    ASSERT_TRUE(v.sdf);
    EXPECT_EQ(v.sdf->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_NEAR(v.sdf->background(), 3 * 0.03, 1e-6); // a band of 3 voxels, as voxelize gives
    EXPECT_NEAR(v.sdf->voxelSize()[0], 0.03, 1e-12);
    // The fog encloses the ball's volume, 4/3 pi r^3.
    const double volume = moments(*v.density).mass * std::pow(0.03, 3);
    EXPECT_NEAR(volume / (4.0 / 3.0 * M_PI * 0.125), 1.0, 0.01);
    expectSphereDistances(*v.sdf, 0.03);
}

TEST(VolumeInput, AFogAloneGetsALevelSetAtHalfDensityInSdfMode)
{
    // Density falls linearly from 1 at radius 0.4 to 0 at 0.6: its 0.5 surface is the sphere of
    // radius 0.5.
    const fs::path file = clouds().dir / "fog.vdb";
    openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(0.0f);
    fog->setName("density");
    fog->setTransform(openvdb::math::Transform::createLinearTransform(0.02));
    auto acc = fog->getAccessor();
    for (auto c = openvdb::CoordBBox(openvdb::Coord(-32), openvdb::Coord(32)).begin(); c; ++c) {
        const double r = fog->indexToWorld(*c).length();
        const float rho = float(std::clamp((0.6 - r) / 0.2, 0.0, 1.0));
        if (rho > 0.0f) acc.setValue(*c, rho);
    }
    openvdb::io::File(file.string()).write({fog});
    EXPECT_FALSE(resampled(volumeSpec(file), 0.03).sdf); // density mode: none
    const VolumeSet v = resampled(volumeSpec(file), 0.03, /*needSdf=*/true);
    ASSERT_TRUE(v.sdf);
    EXPECT_EQ(v.sdf->getGridClass(), openvdb::GRID_LEVEL_SET);
    expectSphereDistances(*v.sdf, 0.03);
}

TEST(VolumeInput, TheObjectTransformPlacesTheVolume)
{
    VolumeSource spec = volumeSpec(clouds().plain);
    const Moments before = moments(*resampled(spec, 0.04).density);
    spec.transform.scale = Vec3d(2.0);
    spec.transform.translate = Vec3d(1.0, 0.0, -0.5);
    const VolumeFileInfo info = inspectVolume(spec);
    EXPECT_NEAR(info.voxelSize, 0.08, 1e-12); // the input's voxels, scaled
    const Moments after = moments(*resampled(spec, 0.04).density);
    const Vec3d expected = 2.0 * before.centroid + Vec3d(1.0, 0.0, -0.5);
    EXPECT_NEAR((after.centroid - expected).length(), 0.0, 0.1 * 0.04);
    EXPECT_NEAR(after.mass / before.mass, 8.0, 0.08); // twice as large in each axis
}

// Resampling onto other voxels gives the same bits at any thread count: OpenVDB's threaded
// resampler made voxels near the input leaves' faces twice, a rounding apart, and kept either (1
// ulp at 20 of cloud-to-bunny's 120,294 voxels, differing run to run at 2 threads).
TEST(VolumeInput, ResamplingIsTheSameAtAnyThreadCount)
{
    const VolumeSource spec = volumeSpec(clouds().plain); // voxels of 0.04
    VolumeSet single;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        single = resampled(spec, 0.032);
    }
    for (int run = 0; run < 4; ++run) {
        tbb::global_control many(tbb::global_control::max_allowed_parallelism, 4);
        const VolumeSet v = resampled(spec, 0.032);
        ASSERT_EQ(v.density->activeVoxelCount(), single.density->activeVoxelCount());
        size_t differ = 0;
        const auto acc = single.density->getConstAccessor();
        for (auto it = v.density->cbeginValueOn(); it; ++it)
            if (acc.getValue(it.getCoord()) != *it) ++differ;
        EXPECT_EQ(differ, 0u) << "run " << run;
    }
}
