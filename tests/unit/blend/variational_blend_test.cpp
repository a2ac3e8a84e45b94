// blend.mode = "variational" through the Morpher: the end frames are the inputs, the velocity is
// the zero set's motion, an influence shape steers the middle, the memory guard refuses before the
// solve, and frames do not depend on the thread count.
#include "support/VoxelizeChecks.h"
#include "support/WarpFixtures.h"
#include "support/ZeroSetTopology.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/MemoryLimit.h>
#include <volmorph/SceneVolumes.h>

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <tbb/global_control.h>

#include <gtest/gtest.h>

#include <tuple>

using namespace volmorph;
using namespace volmorph::test;

namespace {

/// A shape from its level set as voxelize() gives it: the fog, a grey Cd.
VolumeSet fromLevelSet(openvdb::FloatGrid::Ptr sdf)
{
    VolumeSet v;
    v.density = fogFromLevelSet(*sdf, 1.5f * float(sdf->voxelSize()[0]));
    v.density->setTransform(sdf->transformPtr());
    v.color = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.5f));
    v.color->setTransform(sdf->transformPtr());
    v.sdf = sdf;
    return v;
}

openvdb::FloatGrid::Ptr sphereAt(double radius, double x, double voxel)
{
    openvdb::initialize();
    return openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(radius), openvdb::Vec3f(float(x), 0.0f, 0.0f), float(voxel), 3.0f);
}

BlendSpec variational(int constraints)
{
    BlendSpec blend;
    blend.mode = BlendMode::Variational;
    blend.variational.constraints = constraints;
    return blend;
}

} // namespace

// With 5000 constraints per shape at 128 voxels across, the frames at t = 0 and 1 are the inputs:
// IoU at least 0.97 (measured 0.988 and 0.992 on dino-to-eight; without the outward partners 0.962
// at t = 0, Constraints.h).
TEST(VariationalBlend, TheEndFramesAreTheInputs)
{
    const Scene scene = loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" /
                                  "dino-to-eight-variational.toml");
    ASSERT_EQ(scene.blend.mode, BlendMode::Variational);
    ASSERT_EQ(scene.volume.resolution.value_or(0), 128);
    ASSERT_GE(scene.blend.variational.constraints, 5000);
    const SceneVolumes v = voxelizeScene(scene);
    const Morpher morpher(v.source, v.target, scene.pairs, scene.warp, scene.blend);
    const double first = insideIoU(*morpher.frame(0.0).density, *v.source.density);
    const double last = insideIoU(*morpher.frame(1.0).density, *v.target.density);
    std::printf("IoU at t = 0: %.4f, at t = 1: %.4f\n", first, last);
    EXPECT_GE(first, 0.97);
    EXPECT_GE(last, 0.97);
}

// A sphere (radius 0.25) into one of 0.5: the frame's `vel` on its surface is the surface's
// motion, against the radius's rate of change measured from the frames at t +/- 0.05 (a second
// method), in world units per second (a unit of t lasting 2 s).
TEST(VariationalBlend, TheVelocityIsTheZeroSetsMotion)
{
    const double voxel = 0.02;
    const VolumeSet small = voxelized("sphere.obj", voxel, placed(Vec3d(0.0), 0.5)),
                    big = voxelized("sphere.obj", voxel);
    MorphOptions options;
    options.secondsPerUnitT = 2.0;
    const Morpher morpher(small, big, {}, WarpSpec{}, variational(1500), options);
    const double rate = (equivalentRadius(*morpher.frame(0.55).density) -
                         equivalentRadius(*morpher.frame(0.45).density)) /
                        0.1 / options.secondsPerUnitT;
    const VolumeSet mid = morpher.frame(0.5);
    ASSERT_TRUE(mid.velocity);
    auto vel = mid.velocity->getConstAccessor();
    double sum = 0.0, worst = 0.0;
    size_t count = 0;
    for (auto it = mid.sdf->cbeginValueOn(); it; ++it) {
        if (std::abs(*it) > 0.5 * voxel) continue;
        const Vec3d p = mid.sdf->indexToWorld(it.getCoord());
        ASSERT_TRUE(vel.isValueOn(it.getCoord()));
        const double normal = Vec3d(vel.getValue(it.getCoord())).dot(p.unit());
        sum += normal;
        worst = std::max(worst, std::abs(normal - rate));
        ++count;
    }
    ASSERT_GT(count, 1000u);
    std::printf("dr/dt %.4f world units per second; vel . n on the surface: mean %.4f, worst "
                "difference %.4f over %zu voxels\n",
                rate, sum / double(count), worst, count);
    EXPECT_GT(rate, 0.05);
    EXPECT_NEAR(sum / double(count), rate, 0.01 * rate); // measured 0.2%
    EXPECT_LT(worst, 0.05 * rate);                       // measured 1.3%
}

// A sphere (radius 0.25) into a concentric one of 0.5 grows monotonically, frame by frame, from
// one end's radius to the other's (the equivalent radius of the frame's fog).
TEST(VariationalBlend, ASphereIntoALargerOneGrowsMonotonically)
{
    const double voxel = 0.02;
    const VolumeSet small = voxelized("sphere.obj", voxel, placed(Vec3d(0.0), 0.5)),
                    big = voxelized("sphere.obj", voxel);
    const Morpher morpher(small, big, {}, WarpSpec{}, variational(1500));
    double previous = 0.0;
    for (int k = 0; k <= 10; ++k) {
        const double r = equivalentRadius(*morpher.frame(0.1 * k).density);
        std::printf("t %.1f: radius %.4f\n", 0.1 * k, r);
        if (k == 0) {
            EXPECT_NEAR(r, equivalentRadius(*small.density), 0.1 * voxel);
        } else if (k == 10) {
            EXPECT_NEAR(r, equivalentRadius(*big.density), 0.1 * voxel);
        }
        EXPECT_GT(r, previous + 0.005) << "t = " << 0.1 * k;
        previous = r;
    }
}

// A sphere into itself, with a cube (edge 0.9) placed at t = 0.5: the middle frame is closer to
// the cube than without it (IoU), and the ends stay the sphere.
TEST(VariationalBlend, AnInfluenceShapeSteersTheMiddle)
{
    const double voxel = 0.025;
    const VolumeSet sphere = voxelized("sphere.obj", voxel);
    const VolumeSet cube = voxelized("cube.obj", voxel, placed(Vec3d(0.0), 0.9));
    const Morpher plain(sphere, sphere, {}, WarpSpec{}, variational(1500));
    MorphOptions options;
    options.influences = {TimedVolume{cube, 0.5}};
    const Morpher steered(sphere, sphere, {}, WarpSpec{}, variational(1500), options);
    const double without = insideIoU(*plain.frame(0.5).density, *cube.density);
    const double with = insideIoU(*steered.frame(0.5).density, *cube.density);
    const double end = insideIoU(*steered.frame(0.0).density, *sphere.density);
    std::printf("IoU with the cube at t = 0.5: %.4f without it, %.4f with it; at t = 0 with the "
                "sphere %.4f\n",
                without, with, end);
    EXPECT_GT(with, without + 0.05);
    EXPECT_GT(with, 0.9);
    EXPECT_GT(end, 0.95);
}

// A constraint count whose solve would not fit is refused at once, naming the key, before any
// constraint is sampled or solved.
TEST(VariationalBlend, AConstraintCountPastTheMemoryLimitIsRefused)
{
    const VolumeSet sphere = voxelized("sphere.obj", 0.05);
    MorphOptions options;
    options.memoryLimitBytes = residentBytes() + (64ull << 20);
    try {
        const Morpher m(sphere, sphere, {}, WarpSpec{}, variational(1000000), options);
        FAIL() << "not refused";
    } catch (const MemoryLimitExceeded& e) {
        const std::string text = e.what();
        EXPECT_NE(text.find("variational.constraints: 1000000 per shape"), std::string::npos)
            << text;
        EXPECT_NE(text.find("raise the memory limit"), std::string::npos) << text;
        EXPECT_EQ(text.find("--"), std::string::npos) << text;
        EXPECT_GT(e.neededBytes(), e.limitBytes());
    }
}

// The same frame on one thread and on all of them, bit for bit.
TEST(VariationalBlend, FramesDoNotDependOnTheThreadCount)
{
    const double voxel = 0.03;
    const VolumeSet sphere = voxelized("sphere.obj", voxel),
                    cube = voxelized("cube.obj", voxel, placed(Vec3d(0.2, 0.0, 0.0), 0.8));
    MorphOptions options;
    options.secondsPerUnitT = 1.0;
    const auto make = [&] {
        const Morpher m(sphere, cube, {}, WarpSpec{}, variational(800), options);
        return m.frame(0.4);
    };
    const VolumeSet all = make();
    VolumeSet one;
    {
        tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
        one = make();
    }
    ASSERT_EQ(all.sdf->activeVoxelCount(), one.sdf->activeVoxelCount());
    auto a = one.sdf->getConstAccessor();
    auto va = one.velocity->getConstAccessor();
    auto ca = one.color->getConstAccessor();
    for (auto it = all.sdf->cbeginValueOn(); it; ++it) {
        ASSERT_EQ(*it, a.getValue(it.getCoord()));
        ASSERT_EQ(all.velocity->tree().getValue(it.getCoord()), va.getValue(it.getCoord()));
        ASSERT_EQ(all.color->tree().getValue(it.getCoord()), ca.getValue(it.getCoord()));
    }
}

// Issue 40's topology checks through the whole mode (the partition of unity, the sliced frame,
// its redistanced band), each frame's zero set meshed and counted at t = 0, 0.05, ..., 1 (the
// default time scale): a sphere into two separate spheres is one closed shell, then two, never
// another piece; a sphere into a torus goes from Euler characteristic 2 to 0 at one frame.
TEST(VariationalBlend, FramesChangeTopologyOnce)
{
    const double voxel = 0.02;
    auto two = sphereAt(0.25, -0.35, voxel);
    openvdb::tools::csgUnion(*two, *sphereAt(0.25, 0.35, voxel));
    auto torus = torusLevelSet(0.35, 0.12, voxel);
    torus->setTransform(two->transformPtr());
    const VolumeSet one = fromLevelSet(sphereAt(0.3, 0.0, voxel));
    for (const auto& [name, target, first, last] :
         {std::tuple{"two spheres", two, 2L, 4L}, std::tuple{"a torus", torus, 2L, 0L}}) {
        const Morpher m(one, fromLevelSet(target), {}, WarpSpec{}, variational(1500));
        long previous = first;
        int changes = 0;
        for (int k = 0; k <= 20; ++k) {
            const Topology topology = topologyOf(*m.frame(0.05 * k).sdf);
            std::printf("%s, t %.2f: %d shells, Euler %ld\n", name, 0.05 * k, topology.components,
                        topology.euler);
            const int shells = topology.euler == 4 ? 2 : 1;
            EXPECT_EQ(topology.components, shells) << name << ", t = " << 0.05 * k;
            EXPECT_TRUE(topology.euler == first || topology.euler == last)
                << name << ", t = " << 0.05 * k;
            changes += topology.euler != previous;
            previous = topology.euler;
        }
        EXPECT_EQ(previous, last) << name;
        EXPECT_EQ(changes, 1) << name;
    }
}
