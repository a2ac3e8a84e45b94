// The in-between's `vel` grid (density mode): closed forms where the density is above 0.5 (a
// translating sphere, a box turning a quarter turn, a sphere scaling), the centroid's motion
// between frames, and the per-leaf interpolation of the warp's velocity against the exact
// derivative at random voxels of a 16-pair warp.
#include "support/WarpFixtures.h"

#include "blend/VelocityBlend.h" // private to the library; tested directly
#include "warp/VelocityLeaf.h"

using namespace volmorph;
using namespace volmorph::test;

namespace {

/// Frames 1-25 at 24 fps: one unit of t lasts one second.
constexpr double kSecondsPerT = 24.0 / 24.0;

MorphOptions withVelocity()
{
    MorphOptions o;
    o.secondsPerUnitT = kSecondsPerT;
    return o;
}

/// The largest |vel - expected(world point)| over voxels with density above 0.5, relative to
/// the largest expected speed there; also counts those voxels.
template <typename Expected>
double worstError(const VolumeSet& frame, const Expected& expected, int& count)
{
    return worstVelocityError(
        frame, *frame.density, [](float d) { return d > 0.5f; }, expected, count);
}

} // namespace

TEST(Velocity, ATranslatingSphereMovesAtD)
{
    // A point pair moving by d over one second: vel = d everywhere, and the centroid moves at the
    // density-weighted mean velocity (the frames differenced: an independent check).
    const double voxel = 0.04;
    const Vec3d d(1.0, 0.25, 0.0);
    const VolumeSet s = voxelized("sphere.obj", voxel),
                    e = voxelized("sphere.obj", voxel, placed(d));
    const Morpher morpher(s, e, {pair(FeatureType::Point, element(Vec3d(0.0)), element(d))},
                          WarpSpec{}, BlendSpec{}, withVelocity());
    for (double t : {0.25, 0.5}) {
        const VolumeSet frame = morpher.frame(t);
        int count = 0;
        EXPECT_LT(worstError(
                      frame, [&](const Vec3d&) { return d; }, count),
                  0.01)
            << t;
        EXPECT_GT(count, 5000);
        const double h = 0.01;
        const Vec3d rate = (moments(*morpher.frame(t + h).density).centroid -
                            moments(*morpher.frame(t - h).density).centroid) /
                           (2 * h * kSecondsPerT);
        EXPECT_NEAR((rate - d).length(), 0.0, 0.01 * d.length()) << t;
    }
}

TEST(Velocity, TheVelocityCoversTheShuttersReach)
{
    // Moving at |d| = 1.03 world units per second with a reach of 0.25 s: 6.4 voxels of 0.04 ahead
    // of the sphere hold the velocity d too (the warp's own, both sides empty there).
    const double voxel = 0.04;
    const Vec3d d(1.0, 0.25, 0.0);
    const VolumeSet s = voxelized("sphere.obj", voxel),
                    e = voxelized("sphere.obj", voxel, placed(d));
    MorphOptions options = withVelocity();
    options.velocityReachSeconds = 0.25;
    const Morpher morpher(s, e, {pair(FeatureType::Point, element(Vec3d(0.0)), element(d))},
                          WarpSpec{}, BlendSpec{}, options);
    const VolumeSet frame = morpher.frame(0.5);
    auto vel = frame.velocity->getConstAccessor();
    auto density = frame.density->getConstAccessor();
    for (double ahead : {2.0, 5.0, -5.0}) { // voxels past the surface, in front and behind
        const Vec3d p =
            0.5 * d + d.unit() * (ahead > 0 ? 1.0 : -1.0) * (0.5 + std::abs(ahead) * voxel);
        const openvdb::Coord ijk = frame.density->transform().worldToIndexCellCentered(p);
        EXPECT_EQ(density.getValue(ijk), 0.0f) << ahead;
        EXPECT_TRUE(vel.isValueOn(ijk)) << ahead;
        EXPECT_NEAR((Vec3d(vel.getValue(ijk)) - d).length(), 0.0, 0.01 * d.length()) << ahead;
    }
    // Beyond the reach, nothing.
    const Vec3d far = 0.5 * d + d.unit() * (0.5 + 12 * voxel);
    EXPECT_FALSE(vel.isValueOn(frame.density->transform().worldToIndexCellCentered(far)));
}

TEST(Velocity, ABoxTurningAQuarterTurnMovesAsOmegaCrossR)
{
    const OnePairMorph bar = turningBar(0.02);
    const Morpher morpher(bar.source, bar.target, {bar.pair}, WarpSpec{}, BlendSpec{},
                          withVelocity());
    const Vec3d omega(0, 0, M_PI / 2 / kSecondsPerT);
    int count = 0;
    EXPECT_LT(worstError(
                  morpher.frame(0.5), [&](const Vec3d& x) { return omega.cross(x); }, count),
              0.01);
    EXPECT_GT(count, 5000);
}

TEST(Velocity, AScalingSphereMovesAsRTimesTheScaleRate)
{
    const OnePairMorph sphere = doublingSphere(0.02);
    const Morpher morpher(sphere.source, sphere.target, {sphere.pair}, WarpSpec{}, BlendSpec{},
                          withVelocity());
    for (double t : {0.25, 0.75}) {
        int count = 0;
        const double rate = 1.0 / (1.0 + t) / kSecondsPerT; // s(t) = 1 + t
        EXPECT_LT(worstError(
                      morpher.frame(t), [&](const Vec3d& x) { return x * rate; }, count),
                  0.01)
            << t;
        EXPECT_GT(count, 5000);
    }
}

TEST(Velocity, NoVelocityGridUnlessAsked)
{
    const VolumeSet s = voxelized("sphere.obj", 0.05);
    const Morpher morpher(s, s, {}, WarpSpec{}, BlendSpec{});
    EXPECT_FALSE(morpher.frame(0.5).velocity);
}

TEST(Velocity, InterpolatedLeavesMatchTheExactDerivative)
{
    // 16 random pairs over 96 voxels (the warp bench's kind of scene): at 10,000 random voxels of
    // the pairs' region (50 in each of 200 random leaves), each side's velocity from VelocityLeaf
    // is the exact one within 1% of its speed (plus 1e-3 of the region's largest speed, where the
    // speed passes through 0).
    std::mt19937 random(5);
    const auto pairs = randomPairs(random, 16, 96.0);
    const InverseWarp warp(pairs, WarpSpec{}, 0.4);
    const detail::VelocityLeaf leaves(warp);
    std::uniform_int_distribution<int> coordinate(-16, 112), voxel(0, 511);
    std::vector<std::pair<Vec3d, Vec3d>> samples; // (from the leaf, exact)
    double fastest = 0.0;
    int interpolated = 0;
    for (int leaf = 0; leaf < 200; ++leaf) {
        const openvdb::Coord origin =
            openvdb::Coord(coordinate(random), coordinate(random), coordinate(random)) & ~7;
        const openvdb::util::NodeMask<3> on(true);
        Vec3f vs[512], vt[512];
        interpolated += leaves.fill(origin, on, vs, vt);
        for (int n = 0; n < 50; ++n) {
            const openvdb::Index k = openvdb::Index(voxel(random));
            const openvdb::Coord ijk = openvdb::FloatTree::LeafNodeType::offsetToLocalCoord(k);
            InverseWarp::Derivatives ds, dt;
            warp.derivatives((origin + ijk).asVec3d(), ds, dt);
            Vec3d es, et;
            InverseWarp::velocity(ds, es);
            InverseWarp::velocity(dt, et);
            samples.emplace_back(Vec3d(vs[k]), es);
            samples.emplace_back(Vec3d(vt[k]), et);
            fastest = std::max({fastest, es.length(), et.length()});
        }
    }
    EXPECT_GT(interpolated, 100); // of 1600: 16 pairs within 96 voxels bend the field sharply
    int bad = 0;
    for (const auto& [got, exact] : samples)
        if ((got - exact).length() > 0.01 * exact.length() + 1e-3 * fastest) ++bad;
    EXPECT_EQ(bad, 0) << "of " << samples.size() << "; sub-cubes interpolated: " << interpolated;
}

TEST(Velocity, AFewSpikesDoNotSetTheReach)
{
    // 300 leaves moving at 1 unit per second and 2 where the speed spikes to 500 (a fold, a surface
    // splitting): the reach is made for 1. When a tenth of the leaves move at 2, for 2.
    openvdb::Vec3SGrid grid(Vec3f(0.0f));
    for (int i = 0; i < 302; ++i)
        grid.tree().setValueOn(openvdb::Coord(8 * i, 0, 0), Vec3f(i < 300 ? 1.0f : 500.0f, 0, 0));
    EXPECT_FLOAT_EQ(float(detail::VelocityBlend::reachSpeed(grid)), 1.0f);
    for (int i = 270; i < 302; ++i)
        grid.tree().setValueOn(openvdb::Coord(8 * i, 1, 0), Vec3f(0, 2, 0));
    for (int i = 300; i < 302; ++i) grid.tree().setValueOff(openvdb::Coord(8 * i, 0, 0));
    EXPECT_FLOAT_EQ(float(detail::VelocityBlend::reachSpeed(grid)), 2.0f);
    EXPECT_EQ(detail::VelocityBlend::reachSpeed(openvdb::Vec3SGrid(Vec3f(0.0f))), 0.0);
}

TEST(Velocity, TheReachFollowsTheLocalSpeed)
{
    // The bar turning a quarter turn in one second (omega = pi / 2 a second), voxels of 0.02, a
    // reach of 0.25 s: its ends (r = 0.5) move 9.8 voxels within the reach, the middles of its
    // long sides (r = 0.15) 2.9. The velocity reaches past each part of the surface as far as
    // that part moves: far past the ends, close along the middles (a uniform reach, made for the
    // ends, would cover 10 voxels everywhere).
    const double voxel = 0.02;
    const OnePairMorph bar = turningBar(voxel);
    MorphOptions options = withVelocity();
    options.velocityReachSeconds = 0.25;
    const Morpher morpher(bar.source, bar.target, {bar.pair}, WarpSpec{}, BlendSpec{}, options);
    const VolumeSet frame = morpher.frame(0.5); // the bar at 45 degrees
    const Vec3d omega(0, 0, M_PI / 2 / kSecondsPerT);
    const Vec3d along = Vec3d(1, 1, 0).unit(), across = Vec3d(-1, 1, 0).unit();
    auto vel = frame.velocity->getConstAccessor();
    auto density = frame.density->getConstAccessor();
    const auto reached = [&](const Vec3d& from, const Vec3d& direction) {
        int last = -1;
        for (int k = 0; k < 20; ++k) {
            const Vec3d p = from + direction * (k * voxel);
            const openvdb::Coord ijk = frame.velocity->transform().worldToIndexCellCentered(p);
            if (!vel.isValueOn(ijk)) break;
            last = k;
            const Vec3d v = omega.cross(frame.velocity->transform().indexToWorld(ijk));
            if (density.getValue(ijk) == 0.0f) {
                EXPECT_NEAR((Vec3d(vel.getValue(ijk)) - v).length(), 0.0, 0.01 * v.length()) << k;
            }
        }
        return last;
    };
    const int end = reached(along * 0.5, along), side = reached(across * 0.15, across);
    // Steps along the diagonals of x and y: a layer of 26 neighbours is 1.41 of them.
    EXPECT_GE(end, 14); // 2.5 to the density's edge, 11 layers (a 99th-percentile speed)
    EXPECT_LE(side, 9); // 1.5 to the edge, 4 layers (the face's speed within 4 voxels)
    EXPECT_GE(side, 4);
}
