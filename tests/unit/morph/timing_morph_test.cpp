// A morph that travels ([timing], LocalTime.h) in sdf mode (issue 59): a sphere into a cube swept
// upward with spread 0.5 is the cube at the bottom and the sphere at the top half way, one closed
// surface in every frame, the inputs at its ends; the warp of a pair travels the same way; and the
// `vel` grid, with a sweep and with a region, without pairs and with one, is the normal speed the
// frames themselves show (central differences of the frames at each surface voxel), which checks
// the chain rule through tau(x, t); the variational method takes each place at its own time too.
#include "support/WarpFixtures.h"
#include "support/ZeroSetTopology.h"

#include <volmorph/LocalTime.h>

using namespace volmorph;
using namespace volmorph::test;

namespace {

constexpr double kVoxel = 0.02;

/// Upward over the middle three fifths of the shapes (y from -0.5 to 0.5): the bottom fifth
/// starts first, the top fifth last.
std::shared_ptr<const LocalTime> upward(double spread, std::vector<TimingRegion> regions = {})
{
    TimingSettings s;
    s.spread = spread;
    s.sweep = TimingSweep{Vec3d(0.0, -0.3, 0.0), Vec3d(0.0, 1.0, 0.0), 0.6, {}};
    return std::make_shared<const LocalTime>(s, std::move(regions));
}

MorphOptions timed(std::shared_ptr<const LocalTime> time, bool velocity = false)
{
    MorphOptions o;
    o.localTime = std::move(time);
    if (velocity) o.secondsPerUnitT = 1.0;
    return o;
}

BlendSpec sdfMode()
{
    BlendSpec b;
    b.mode = BlendMode::Sdf;
    return b;
}

/// Intersection over union of the insides (sdf < 0) of two level sets over the voxels of `box`.
double insideIoU(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b,
                 const openvdb::CoordBBox& box)
{
    auto ra = a.getConstAccessor();
    auto rb = b.getConstAccessor();
    size_t both = 0, either = 0;
    for (auto it = box.begin(); it; ++it) {
        const bool ia = ra.getValue(*it) < 0.0f, ib = rb.getValue(*it) < 0.0f;
        both += ia && ib;
        either += ia || ib;
    }
    return either ? double(both) / double(either) : 1.0;
}

/// The voxels of the slab lo <= y <= hi world units across the shapes' box.
openvdb::CoordBBox slab(double lo, double hi)
{
    const int x = int(std::ceil(0.6 / kVoxel));
    return openvdb::CoordBBox(openvdb::Coord(-x, int(std::ceil(lo / kVoxel)), -x),
                              openvdb::Coord(x, int(std::floor(hi / kVoxel)), x));
}

/// True when the local time at every voxel within `kStencil` of c stays strictly between 0 and 1
/// from t - h to t + h: the frames' differences and the velocity's own stencils (its gradients,
/// central differences) do not reach a place where the morph starts or ends, where tau has a kink.
bool inRamp(const openvdb::FloatGrid& grid, const LocalTime& time, const openvdb::Coord& c,
            double t, double h)
{
    constexpr int kStencil = 2;
    for (int i = -kStencil; i <= kStencil; ++i)
        for (int j = -kStencil; j <= kStencil; ++j)
            for (int k = -kStencil; k <= kStencil; ++k) {
                const Vec3d x = grid.indexToWorld(c.offsetBy(i, j, k));
                if (!(time.at(x, t - h).tau > 0.0 && time.at(x, t + h).tau < 1.0)) return false;
            }
    return true;
}

/// Over the surface voxels of frame t (|sdf| below half a voxel) whose neighbourhood stays in the
/// ramp from t - h to t + h (inRamp): the mean |vel . n - v_n| over the mean |v_n|, v_n =
/// -phi_t / |grad phi| the level set's normal speed from the frames themselves (phi_t their
/// central difference over 2h; n and |grad phi| from phi(t)'s central differences: in the band
/// the frames hold the blend, not a distance, so |grad phi| is not 1).
double normalSpeedError(const Morpher& morpher, const LocalTime& time, double t, double h,
                        int& count)
{
    const VolumeSet now = morpher.frame(t), before = morpher.frame(t - h),
                    after = morpher.frame(t + h);
    auto phi = now.sdf->getConstAccessor();
    auto p0 = before.sdf->getConstAccessor();
    auto p1 = after.sdf->getConstAccessor();
    auto vel = now.velocity->getConstAccessor();
    double error = 0.0, speed = 0.0;
    count = 0;
    for (auto it = now.sdf->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        if (!(std::abs(*it) < 0.5 * kVoxel) || !vel.isValueOn(c)) continue;
        const double rate = (double(p1.getValue(c)) - double(p0.getValue(c))) / (2.0 * h);
        Vec3d n;
        for (int k = 0; k < 3; ++k) {
            openvdb::Coord step(0);
            step[k] = 1;
            n[k] =
                (double(phi.getValue(c + step)) - double(phi.getValue(c - step))) / (2.0 * kVoxel);
        }
        const double vn = -rate / n.length();           // the level set's normal speed
        if (!inRamp(*now.sdf, time, c, t, h)) continue; // the morph starts or ends near
        error += std::abs(Vec3d(vel.getValue(c)).dot(n.unit()) - vn);
        speed += std::abs(vn);
        ++count;
    }
    return count ? error / speed : 1e9;
}

} // namespace

TEST(TimingMorph, ASweptSphereIntoACubeIsTheCubeBelowAndTheSphereAboveHalfWay)
{
    const VolumeSet sphere = voxelized("sphere.obj", kVoxel), cube = voxelized("cube.obj", kVoxel);
    const Morpher morpher(sphere, cube, {}, WarpSpec{}, sdfMode(), timed(upward(0.5)));
    const VolumeSet half = morpher.frame(0.5);
    // The bottom fifth is the target's, the top fifth the source's.
    EXPECT_GE(insideIoU(*half.sdf, *cube.sdf, slab(-0.55, -0.3)), 0.95);
    EXPECT_GE(insideIoU(*half.sdf, *sphere.sdf, slab(0.3, 0.55)), 0.95);
    // Not the morph without a timing, which is half way everywhere.
    const Morpher plain(sphere, cube, {}, WarpSpec{}, sdfMode());
    EXPECT_LT(insideIoU(*plain.frame(0.5).sdf, *cube.sdf, slab(-0.55, -0.3)), 0.95);
    // The ends are the inputs, and every frame is one closed surface (a sphere's topology).
    EXPECT_GE(insideIoU(*morpher.frame(0.0).sdf, *sphere.sdf, slab(-0.6, 0.6)), 0.99);
    EXPECT_GE(insideIoU(*morpher.frame(1.0).sdf, *cube.sdf, slab(-0.6, 0.6)), 0.99);
    for (double t = 0.0; t <= 1.0001; t += 0.125) {
        const Topology topology = topologyOf(*morpher.frame(t).sdf);
        EXPECT_EQ(topology.components, 1) << "t " << t;
        EXPECT_EQ(topology.euler, 2) << "t " << t;
    }
}

TEST(TimingMorph, ARegionThatStartsAtOnceIsDoneWhileTheRestHasNotBegun)
{
    // A sweep whose delay is the spread everywhere (its plane far below), and a region, the
    // ball about (0, -0.5, 0) of radius 0.45, that starts at 0 with a softness of 0.15: inside it
    // the morph is over by t = 1 - spread, outside it has not begun at t = spread.
    constexpr double kSpread = 0.4;
    TimingSettings settings;
    settings.spread = kSpread;
    settings.sweep = TimingSweep{Vec3d(0.0, -10.0, 0.0), Vec3d(0.0, 1.0, 0.0), 1.0, {}};
    const auto ball = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        0.45f, openvdb::Vec3f(0.0f, -0.5f, 0.0f), float(kVoxel), 10.0f); // reaches the softness
    const auto time =
        std::make_shared<const LocalTime>(settings, std::vector{TimingRegion{ball, 0.0, 0.15}});
    const VolumeSet sphere = voxelized("sphere.obj", kVoxel), cube = voxelized("cube.obj", kVoxel);
    const Morpher morpher(sphere, cube, {}, WarpSpec{}, sdfMode(), timed(time));
    // Inside the region: the box |x|, |z| <= 0.2, -0.6 <= y <= -0.2, all inside the ball.
    const int r = int(0.2 / kVoxel);
    const openvdb::CoordBBox inside(openvdb::Coord(-r, int(-0.6 / kVoxel), -r),
                                    openvdb::Coord(r, int(-0.2 / kVoxel), r));
    const VolumeSet early = morpher.frame(kSpread), late = morpher.frame(1.0 - kSpread);
    EXPECT_GE(insideIoU(*late.sdf, *cube.sdf, inside), 0.99);
    EXPECT_LT(insideIoU(*early.sdf, *cube.sdf, inside), 0.99); // under way
    // Outside it (above y = 0.12: beyond the ball's softness), the source's until t = spread.
    EXPECT_GE(insideIoU(*early.sdf, *sphere.sdf, slab(0.12, 0.6)), 0.99);
    EXPECT_LT(insideIoU(*late.sdf, *sphere.sdf, slab(0.12, 0.6)), 0.99);
}

TEST(TimingMorph, DensityModeBlendsEachPlaceAtItsOwnTime)
{
    // Half way, the bottom fifth's fog is the cube's and the top fifth's the sphere's; in between
    // each voxel is the blend at its own tau.
    BlendSpec density;
    density.mode = BlendMode::Density;
    const VolumeSet sphere = voxelized("sphere.obj", kVoxel), cube = voxelized("cube.obj", kVoxel);
    const auto time = upward(0.5);
    const Morpher morpher(sphere, cube, {}, WarpSpec{}, density, timed(time));
    const VolumeSet half = morpher.frame(0.5);
    auto out = half.density->getConstAccessor();
    auto a = sphere.density->getConstAccessor();
    auto b = cube.density->getConstAccessor();
    double worst = 0.0;
    for (auto it = slab(-0.6, 0.6).begin(); it; ++it) {
        const double tau = time->at(half.density->indexToWorld(*it), 0.5).tau;
        const double expected = (1.0 - tau) * a.getValue(*it) + tau * b.getValue(*it);
        worst = std::max(worst, std::abs(double(out.getValue(*it)) - expected));
    }
    EXPECT_LT(worst, 1e-6);
    // The fifths: wholly the target's below, the source's above.
    EXPECT_EQ(time->at(Vec3d(0, -0.35, 0), 0.5).tau, 1.0);
    EXPECT_EQ(time->at(Vec3d(0, 0.35, 0), 0.5).tau, 0.0);
}

TEST(TimingMorph, DensityModeWarpsEachPlaceAtItsOwnTimeToo)
{
    // A pair moving the sphere by 0.25 along x, in density mode under the upward sweep: half way,
    // the bottom fifth is done (tau 1: the target's own voxels, its warp the identity there) and
    // the top fifth has not begun (tau 0: the source's).
    BlendSpec density;
    density.mode = BlendMode::Density;
    const VolumeSet big = exactSphere(0.5, kVoxel),
                    moved = exactSphere(0.5, kVoxel, 3.0f, Vec3d(0.25, 0.0, 0.0));
    const std::vector<FeaturePairSpec> pairs{
        pair(FeatureType::Point, element(Vec3d(0.0)), element(Vec3d(0.25, 0.0, 0.0)))};
    const Morpher morpher(big, moved, pairs, WarpSpec{}, density, timed(upward(0.5)));
    const VolumeSet half = morpher.frame(0.5);
    auto out = half.density->getConstAccessor();
    auto a = big.density->getConstAccessor();
    auto b = moved.density->getConstAccessor();
    double below = 0.0, above = 0.0;
    for (auto it = slab(-0.6, -0.35).begin(); it; ++it)
        below = std::max(below, std::abs(double(out.getValue(*it)) - b.getValue(*it)));
    for (auto it = slab(0.35, 0.6).begin(); it; ++it)
        above = std::max(above, std::abs(double(out.getValue(*it)) - a.getValue(*it)));
    EXPECT_LT(below, 1e-4);
    EXPECT_LT(above, 1e-4);
    EXPECT_GT(half.density->activeVoxelCount(), 0u);
}

TEST(TimingMorph, VelocityUnderASweepOrARegionIsTheFramesOwnNormalSpeed)
{
    // Concentric exact spheres (radii 0.5 and 0.4, bands wide enough to hold every in-between's
    // surface): the surface moves only by the blend, at each place on its own time.
    const VolumeSet big = exactSphere(0.5, kVoxel, 8.0f), small = exactSphere(0.4, kVoxel, 8.0f);
    const auto region = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        0.25f, openvdb::Vec3f(0.4f, 0.2f, 0.0f), float(kVoxel), 12.0f);
    const std::pair<const char*, std::shared_ptr<const LocalTime>> timings[] = {
        {"sweep", upward(0.5)}, {"region", upward(0.5, {TimingRegion{region, 0.0, 0.15}})}};
    for (const auto& [name, time] : timings) {
        const Morpher morpher(big, small, {}, WarpSpec{}, sdfMode(), timed(time, true));
        for (double t : {name[0] == 's' ? 0.6 : 0.35}) {
            int count = 0;
            EXPECT_LT(normalSpeedError(morpher, *time, t, 0.01, count), 0.01) << name << " t " << t;
            EXPECT_GT(count, 500) << name << " t " << t;
        }
    }
}

TEST(TimingMorph, WithPairsTheWarpTravelsTooAndItsVelocityIsTheFramesOwn)
{
    // A sphere (radius 0.5) into a smaller one (0.4) moved by 0.25 along x, through one box pair
    // that says so: each place is warped at its own local time. Half way under the upward sweep,
    // the bottom fifth is the target's and the top fifth the source's, not the morph at 0.5
    // everywhere; `vel` is the frames' own normal speed with a sweep and with a region. The
    // frames take the exact warp: the table's velocity (TimedWarp.h) is its map's derivative
    // between two levels, which changes at each level, and a central difference over 2h = 0.02
    // (tau moves by 0.04) spans levels 1/64 apart (with the table: 0.9% with the sweep, 1.4% with
    // the region; the table's own velocity against its map within one interval is
    // timed_warp_test.cpp's).
    WarpSpec exact;
    exact.toleranceVoxels = 0.0;
    const VolumeSet big = exactSphere(0.5, kVoxel, 8.0f),
                    small = exactSphere(0.4, kVoxel, 8.0f, Vec3d(0.25, 0.0, 0.0));
    const std::vector<FeaturePairSpec> pairs{
        pair(FeatureType::Box, element(Vec3d(0.0)),
             element(Vec3d(0.25, 0.0, 0.0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0.8)))};
    const auto region = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        0.25f, openvdb::Vec3f(0.4f, 0.2f, 0.0f), float(kVoxel), 24.0f); // reaches its softness
    const std::pair<const char*, std::shared_ptr<const LocalTime>> timings[] = {
        {"sweep", upward(0.5)}, {"region", upward(0.5, {TimingRegion{region, 0.0, 0.4}})}};
    for (const auto& [name, time] : timings) {
        const Morpher morpher(big, small, pairs, exact, sdfMode(), timed(time, true));
        if (name[0] == 's') {
            const VolumeSet half = morpher.frame(0.5);
            EXPECT_GE(insideIoU(*half.sdf, *small.sdf, slab(-0.55, -0.3)), 0.95);
            EXPECT_GE(insideIoU(*half.sdf, *big.sdf, slab(0.3, 0.55)), 0.95);
            const Morpher plain(big, small, pairs, WarpSpec{}, sdfMode());
            EXPECT_LT(insideIoU(*plain.frame(0.5).sdf, *small.sdf, slab(-0.55, -0.3)), 0.95);
        }
        const double t = name[0] == 's' ? 0.6 : 0.35;
        int count = 0;
        EXPECT_LT(normalSpeedError(morpher, *time, t, 0.01, count), 0.01) << name << " t " << t;
        EXPECT_GT(count, 500) << name << " t " << t;
    }
}

TEST(TimingMorph, TheVariationalMethodTakesEachPlaceAtItsOwnTime)
{
    // Turk and O'Brien's method, a sphere into a cube swept upward: each place is the function at
    // its own local time, so half way the bottom fifth (tau 1) is the same function's last slice
    // and the top fifth (tau 0) its first, as the morph without a timing gives them (measured: the
    // same voxels); one closed surface in every frame; `vel` against the frames' own normal speed
    // is as close as the method's own without a timing (1.6% and 1.7%: the variational velocity
    // is the zero set's motion in the band, which the frames' differences measure only to about
    // that): the chain rule through tau adds no error.
    BlendSpec variational;
    variational.mode = BlendMode::Variational;
    variational.variational.constraints = 1500;
    const VolumeSet sphere = voxelized("sphere.obj", kVoxel), cube = voxelized("cube.obj", kVoxel);
    const auto time = upward(0.5);
    const Morpher morpher(sphere, cube, {}, WarpSpec{}, variational, timed(time, true));
    const Morpher plain(sphere, cube, {}, WarpSpec{}, variational, timed(nullptr, true));
    const VolumeSet half = morpher.frame(0.5), first = plain.frame(0.0), last = plain.frame(1.0);
    EXPECT_GE(insideIoU(*half.sdf, *last.sdf, slab(-0.55, -0.3)), 0.99);
    EXPECT_GE(insideIoU(*half.sdf, *first.sdf, slab(0.3, 0.55)), 0.99);
    EXPECT_LT(insideIoU(*plain.frame(0.5).sdf, *last.sdf, slab(-0.55, -0.3)), 0.95);
    for (double t : {0.25, 0.5, 0.75}) {
        const Topology topology = topologyOf(t == 0.5 ? *half.sdf : *morpher.frame(t).sdf);
        EXPECT_EQ(topology.components, 1) << "t " << t;
        EXPECT_EQ(topology.euler, 2) << "t " << t;
    }
    int count = 0, plainCount = 0;
    const double error = normalSpeedError(morpher, *time, 0.6, 0.01, count);
    const LocalTime everywhere; // tau = t: every place in the ramp
    const double plainError = normalSpeedError(plain, everywhere, 0.6, 0.01, plainCount);
    std::printf("variational, vel against the frames' normal speed: %.2f%% under a sweep (%d "
                "voxels), %.2f%% without a timing (%d voxels)\n",
                100.0 * error, count, 100.0 * plainError, plainCount);
    EXPECT_LT(error, plainError + 0.002);
    EXPECT_LT(error, 0.02);
    EXPECT_GT(count, 500);
}
