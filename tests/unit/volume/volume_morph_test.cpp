// Morphs of a volume input (the test data generator's cloud, with a temperature grid) into a mesh:
// the ends are the inputs, the temperature follows its schedule in every in-between (a closed form:
// the cloud's temperature is linear, 1 - y), a rotated finer copy of the cloud gives the same
// frames, and a fog morphs in sdf mode through its derived level set.
#include "support/VolumeFixtures.h"

#include <volmorph/core/VdbRead.h>
#include <volmorph/Frames.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/Schedule.h>

using namespace volmorph;
using namespace volmorph::test;
using volmorph::test::cloud::clouds;

namespace {

constexpr double kVoxel = 0.04;

/// The cloud (or its rotated copy) into the sphere mesh (radius 0.5) placed to its right: one box
/// pair from the cloud's bounds to the sphere's, temperature on a smoothstep.
Scene cloudToSphere(const std::filesystem::path& cloudFile, const std::string& extra = "")
{
    const std::string text =
        "[source]\nvolume = \"" + cloudFile.string() +
        "\"\n"
        "[target]\nmesh = \"" +
        (kMeshes / "sphere.obj").string() +
        "\"\ntransform = { translate = [1.5, 0.45, 0] }\n"
        "[volume]\nvoxel_size = " +
        std::to_string(kVoxel) +
        "\n"
        "[[pair]]\ntype = \"box\"\n"
        "source = { origin = [0, 0.5, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [1.8, 1.1, 1.2] "
        "}\n"
        "target = { origin = [1.5, 0.45, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [1, 1, 1] }\n"
        "[blend]\ngrids = { temperature = \"smoothstep\" }\n" +
        extra + "[frames]\nrange = \"0-4\"\noutput = \"o.####.exr\"\n";
    return parseScene(text, clouds().dir / "scene.toml");
}

const openvdb::FloatGrid& floatGrid(const VolumeSet& v, const std::string& name)
{
    return static_cast<const openvdb::FloatGrid&>(*v.extras.at(name));
}

} // namespace

TEST(VolumeMorph, TheEndsAreTheCloudAndTheMesh)
{
    const Scene scene = cloudToSphere(clouds().plain);
    const SceneVolumes v = voxelizeScene(scene);
    WarpSpec exact = scene.warp;
    exact.toleranceVoxels = 0.0; // at t = 0 and 1 the exact warp is each side's identity
    const Morpher morpher(v.source, v.target, scene.pairs, exact, scene.blend);
    const VolumeSet first = morpher.frame(0.0), last = morpher.frame(1.0);
    EXPECT_LT(relativeL1(*first.density, *v.source.density), 1e-4);
    EXPECT_LT(relativeL1(*last.density, *v.target.density), 1e-4);
    // The temperature is the cloud's at t = 0, and the target's background (it has none) at 1.
    EXPECT_LT(relativeL1(floatGrid(first, "temperature"), floatGrid(v.source, "temperature")),
              1e-4);
    const openvdb::FloatGrid& end = floatGrid(last, "temperature");
    EXPECT_EQ(end.background(), 0.0f);
    for (auto it = end.cbeginValueOn(); it; ++it) EXPECT_EQ(*it, 0.0f);
}

TEST(VolumeMorph, TemperatureFollowsItsScheduleInEveryInBetween)
{
    // Where the warped point's trilinear cell lies inside the cloud's temperature, the in-between's
    // temperature is (1 - tau(t)) (1 - y) at the source point W_S(x) (the target carries none, so
    // its side is the background 0). The approximated warp moves W_S by at most its tolerance, and
    // the temperature changes by 1 per world unit.
    const Scene scene = cloudToSphere(clouds().plain);
    const SceneVolumes v = voxelizeScene(scene);
    const Morpher morpher(v.source, v.target, scene.pairs, scene.warp, scene.blend);
    const openvdb::FloatGrid& source = floatGrid(v.source, "temperature");
    auto inside = source.getConstAccessor();
    for (double t : {0.25, 0.5, 0.75}) {
        const VolumeSet frame = morpher.frame(t);
        const double tau = scheduleValue(scene.blend.grids.at("temperature").schedule, t);
        const InverseWarp warp(scene.pairs, scene.warp, t, 1.0 / kVoxel);
        const double bound = (1.0 - tau) * scene.warp.toleranceVoxels * kVoxel + 1e-5;
        int checked = 0;
        const openvdb::FloatGrid& temperature = floatGrid(frame, "temperature");
        for (auto it = temperature.cbeginValueOn(); it; ++it) {
            Vec3d ps, pt;
            warp.map(it.getCoord().asVec3d(), ps, pt);
            const openvdb::Coord c = openvdb::Coord::floor(ps);
            bool interior = true;
            for (int k = 0; k < 8 && interior; ++k)
                interior = inside.isValueOn(c.offsetBy(k & 1, (k >> 1) & 1, (k >> 2) & 1));
            if (!interior) continue;
            const double expected = (1.0 - tau) * (1.0 - source.indexToWorld(ps).y());
            EXPECT_NEAR(*it, expected, bound) << "t " << t << " at " << it.getCoord();
            ++checked;
        }
        EXPECT_GT(checked, 2000) << "t " << t;
    }
}

TEST(VolumeMorph, ARotatedFinerCopyGivesTheSameFrames)
{
    // The frames of the two copies differ no more than the inputs do (the same warp reads both).
    const Scene a = cloudToSphere(clouds().plain), b = cloudToSphere(clouds().rotated);
    const SceneVolumes va = voxelizeScene(a), vb = voxelizeScene(b);
    const double inputs = relativeL1(*va.source.density, *vb.source.density);
    const double temperatures =
        relativeL1(floatGrid(va.source, "temperature"), floatGrid(vb.source, "temperature"));
    const Morpher ma(va.source, va.target, a.pairs, a.warp, a.blend);
    const Morpher mb(vb.source, vb.target, b.pairs, b.warp, b.blend);
    for (double t : {0.25, 0.5}) {
        const VolumeSet fa = ma.frame(t), fb = mb.frame(t);
        EXPECT_LT(relativeL1(*fa.density, *fb.density), 1.2 * inputs) << "t " << t;
        EXPECT_LT(relativeL1(floatGrid(fa, "temperature"), floatGrid(fb, "temperature")),
                  1.2 * temperatures)
            << "t " << t;
    }
}

TEST(VolumeMorph, EachFrameOfASequenceReadsItsOwnInputFrame)
{
    // The cloud drifting 0.1 world units along x per frame, frames 1-5 on disk; the scene runs
    // 0-7: frame 0 holds input 1, frames 6 and 7 hold input 5.
    const std::filesystem::path dir = clouds().dir / "drift";
    std::filesystem::create_directories(dir);
    const openvdb::GridPtrVecPtr grids = readVdbGrids(clouds().plain);
    for (int f = 1; f <= 5; ++f) {
        openvdb::GridPtrVec moved;
        for (const auto& g : *grids) {
            openvdb::GridBase::Ptr c = g->copyGrid();
            openvdb::math::Transform::Ptr xf = g->transform().copy();
            xf->postTranslate(openvdb::Vec3d(0.1 * f, 0.0, 0.0));
            c->setTransform(xf);
            moved.push_back(c);
        }
        openvdb::io::File(frameFileName((dir / "drift.####.vdb").string(), f)).write(moved);
    }
    Scene scene = cloudToSphere(dir / "drift.####.vdb");
    ASSERT_EQ(scene.source.volumeFrames, (std::vector<int>{1, 2, 3, 4, 5}));
    scene.frames.first = 0;
    scene.frames.last = 7;
    const double x0 = moments(*voxelizeScene(sceneAtFrame(scene, 1)).source.density).centroid.x();
    for (int f = 0; f <= 7; ++f) {
        const int input = std::clamp(f, 1, 5);
        const Scene at = sceneAtFrame(scene, f);
        EXPECT_EQ(at.source.volume.filename(), "drift.000" + std::to_string(input) + ".vdb");
        const Moments m = moments(*voxelizeScene(at).source.density);
        EXPECT_NEAR(m.centroid.x() - x0, 0.1 * (input - 1), 0.05 * kVoxel) << "frame " << f;
    }
}

TEST(VolumeMorph, AFogMorphsInSdfModeThroughItsDerivedLevelSet)
{
    const Scene scene = cloudToSphere(clouds().plain, "mode = \"sdf\"\n");
    const SceneVolumes v = voxelizeScene(scene);
    ASSERT_TRUE(v.source.sdf); // derived from the density at 0.5
    const Morpher morpher(v.source, v.target, scene.pairs, scene.warp, scene.blend);
    const VolumeSet frame = morpher.frame(0.5);
    ASSERT_TRUE(frame.sdf);
    EXPECT_GT(frame.density->activeVoxelCount(), 1000u);
    // Temperature rides on the kept band, as Cd does in sdf mode.
    const openvdb::FloatGrid& temperature = floatGrid(frame, "temperature");
    EXPECT_EQ(temperature.activeVoxelCount(), frame.color->activeVoxelCount());
    EXPECT_GT(temperature.activeVoxelCount(), 1000u);
}
