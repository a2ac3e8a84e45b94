// The in-between's `vel` grid in sdf mode: the level set's motion. Closed forms on the surface
// (|phi| below a voxel): concentric spheres with no pairs move along their normals at dr/dt (a
// linear and a smoothstep schedule), and the radius of the frames themselves, differenced, agrees;
// a translating sphere keeps v = d and a turning bar w x r (the warp's tangential part is kept,
// its normal part matches the field's).
#include "support/WarpFixtures.h"

#include <volmorph/Schedule.h>
#include <volmorph/Voxelize.h>

using namespace volmorph;
using namespace volmorph::test;

namespace {

/// One unit of t lasts one second.
MorphOptions withVelocity()
{
    MorphOptions o;
    o.secondsPerUnitT = 1.0;
    return o;
}

BlendSpec sdfBlend()
{
    BlendSpec b;
    b.mode = BlendMode::Sdf;
    return b;
}

/// The largest |vel - expected(world point)| over the surface's voxels (|sdf| below a voxel),
/// relative to the largest expected speed there; also counts those voxels.
template <typename Expected>
double worstOnSurface(const VolumeSet& frame, const Expected& expected, int& count)
{
    const float voxel = float(frame.sdf->voxelSize()[0]);
    return worstVelocityError(
        frame, *frame.sdf, [voxel](float d) { return std::abs(d) < voxel; }, expected, count);
}

} // namespace

TEST(SdfVelocity, ConcentricSpheresMoveAlongTheirNormalsAtDrDt)
{
    // Exact spheres of radii r0 and r1 about the origin, no pairs: the in-between's radius is
    // r(t) = (1 - tau(t)) r0 + tau(t) r1, so v = tau'(t) (r1 - r0) p / |p|. The frames' own radius,
    // differenced in t, agrees with the schedule's secant. Two voxels apart, the in-between's
    // surface lies where both distances are the bands' own (exact); far apart see below.
    const double voxel = 0.01, r0 = 0.5, r1 = 0.48;
    const VolumeSet big = exactSphere(r0, voxel), small = exactSphere(r1, voxel);
    for (const auto kind : {ScheduleSpec::Kind::Linear, ScheduleSpec::Kind::Smoothstep}) {
        BlendSpec blend = sdfBlend();
        blend.sdf.kind = kind;
        const Morpher morpher(big, small, {}, WarpSpec{}, blend, withVelocity());
        for (double t : {0.3, 0.6}) {
            const double drdt = scheduleSlope(blend.sdf, t) * (r1 - r0);
            int count = 0;
            EXPECT_LT(worstOnSurface(
                          morpher.frame(t), [&](const Vec3d& p) { return drdt * p.unit(); }, count),
                      0.01)
                << describe(blend.sdf) << " at t = " << t;
            EXPECT_GT(count, 10000);
            const double h = 0.1;
            const double differenced = (equivalentRadius(*morpher.frame(t + h).density) -
                                        equivalentRadius(*morpher.frame(t - h).density)) /
                                       (2 * h);
            const double secant =
                (scheduleValue(blend.sdf, t + h) - scheduleValue(blend.sdf, t - h)) / (2 * h);
            EXPECT_NEAR(differenced, secant * (r1 - r0), 0.01 * std::abs(drdt))
                << describe(blend.sdf);
        }
    }
}

TEST(SdfVelocity, FarApartSpheresMoveAsTheirFramesDo)
{
    // Spheres of radii 0.5 and 0.25: the in-between's surface lies in both sides' extended fields,
    // first-order distances (ExtendedDistance.h), so the frames' radius moves up to 2% off the
    // closed form. The velocity follows the frames: the mean normal speed on the surface equals
    // their radius differenced in t within 1%, and each voxel is within 3% of the closed form.
    const double voxel = 0.01, r0 = 0.5, r1 = 0.25;
    const Morpher morpher(exactSphere(r0, voxel), exactSphere(r1, voxel), {}, WarpSpec{},
                          sdfBlend(), withVelocity());
    for (double t : {0.3, 0.6}) {
        const VolumeSet frame = morpher.frame(t);
        int count = 0;
        EXPECT_LT(worstOnSurface(
                      frame, [&](const Vec3d& p) { return (r1 - r0) * p.unit(); }, count),
                  0.03)
            << t;
        auto vel = frame.velocity->getConstAccessor();
        double sum = 0.0;
        for (auto it = frame.sdf->cbeginValueOn(); it; ++it)
            if (std::abs(*it) < voxel)
                sum += Vec3d(vel.getValue(it.getCoord()))
                           .dot(frame.sdf->indexToWorld(it.getCoord()).unit());
        const double h = 0.05;
        const double differenced = (equivalentRadius(*morpher.frame(t + h).density) -
                                    equivalentRadius(*morpher.frame(t - h).density)) /
                                   (2 * h);
        EXPECT_NEAR(sum / count, differenced, 0.01 * std::abs(differenced)) << t;
    }
}

TEST(SdfVelocity, ATranslatingSphereMovesAtD)
{
    const double voxel = 0.02;
    const Vec3d d(1.0, 0.25, 0.0);
    const VolumeSet s = voxelized("sphere.obj", voxel),
                    e = voxelized("sphere.obj", voxel, placed(d));
    const Morpher morpher(s, e, {pair(FeatureType::Point, element(Vec3d(0.0)), element(d))},
                          WarpSpec{}, sdfBlend(), withVelocity());
    int count = 0;
    EXPECT_LT(worstOnSurface(
                  morpher.frame(0.4), [&](const Vec3d&) { return d; }, count),
              0.01);
    EXPECT_GT(count, 3000);
}

TEST(SdfVelocity, ATurningBarKeepsTheWarpsTangentialMotion)
{
    const OnePairMorph bar = turningBar(0.02);
    const Morpher morpher(bar.source, bar.target, {bar.pair}, WarpSpec{}, sdfBlend(),
                          withVelocity());
    const Vec3d omega(0, 0, M_PI / 2);
    int count = 0;
    EXPECT_LT(worstOnSurface(
                  morpher.frame(0.5), [&](const Vec3d& x) { return omega.cross(x); }, count),
              0.01);
    EXPECT_GT(count, 3000);
}

TEST(SdfVelocity, TheReachCarriesTheNormalSpeed)
{
    // Growing spheres (no pairs, no warp velocity): 3 and 6 voxels past the band, out to the
    // reach, the velocity is still dr/dt along the normal, within the far field's error (its
    // level sets there move a few percent off the surface's; FarApartSpheresMoveAsTheirFramesDo).
    const double voxel = 0.02, r0 = 0.25, r1 = 0.5;
    MorphOptions options = withVelocity();
    options.velocityReachSeconds = 1.0; // at 0.25 world units a second: 13 voxels
    const Morpher morpher(exactSphere(r0, voxel), exactSphere(r1, voxel), {}, WarpSpec{},
                          sdfBlend(), options);
    const VolumeSet frame = morpher.frame(0.5);
    const double r = 0.5 * (r0 + r1), drdt = r1 - r0;
    auto vel = frame.velocity->getConstAccessor();
    const double band = frame.sdf->background() / voxel;
    for (double past : {band + 3.0, band + 6.0, -(band + 3.0)}) {
        const Vec3d p = Vec3d(0.6, 0.0, 0.8) * (r + past * voxel);
        const openvdb::Coord ijk = frame.sdf->transform().worldToIndexCellCentered(p);
        EXPECT_TRUE(vel.isValueOn(ijk)) << past;
        // Measured 1.6%, 1.6% and 5.1%; 2.7%, 3.0% and 4.5% with the swept far field of before
        // issue 38, whose distances were 0.5 to 1 voxel off here against 0.05 now: the error
        // inside comes from the velocity's extrapolation inward, not from the distances.
        EXPECT_NEAR((Vec3d(vel.getValue(ijk)) - drdt * p.unit()).length(), 0.0, 0.06 * drdt)
            << past;
    }
}
