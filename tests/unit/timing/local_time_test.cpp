// The delay field and local time (LocalTime.h) against their definitions: the sweep's ramp (0 at
// its plane, the spread at its length, linear between but for its rounded ends, C1), tau's clamp
// and both ends of the morph, the derivatives against central differences, and a region (a
// sphere's level set) overriding the sweep inside it and fading over its softness.
#include <volmorph/LocalTime.h>

#include <gtest/gtest.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <random>

using namespace volmorph;

namespace {

TimingSettings upward(double spread)
{
    TimingSettings s;
    s.spread = spread;
    s.sweep = TimingSweep{Vec3d(0.0, -0.5, 0.0), Vec3d(0.0, 2.0, 0.0), 1.0, {}};
    return s;
}

/// Central differences of the delay at x, step h world units.
Vec3d delayDifference(const LocalTime& time, const Vec3d& x, double h)
{
    Vec3d g;
    for (int k = 0; k < 3; ++k) {
        Vec3d step(0.0);
        step[k] = h;
        g[k] = (time.delay(x + step).d - time.delay(x - step).d) / (2.0 * h);
    }
    return g;
}

} // namespace

TEST(LocalTime, TheSweepRampsFromItsPlaneToItsLengthAndIsC1)
{
    const LocalTime time(upward(0.5), {});
    EXPECT_TRUE(time.active());
    EXPECT_EQ(time.delay(Vec3d(0.3, -0.5, 0.2)).d, 0.0);
    EXPECT_EQ(time.delay(Vec3d(0.0, -2.0, 0.0)).d, 0.0);          // clamped behind
    EXPECT_EQ(time.delay(Vec3d(0.0, 0.5, 0.0)).d, 0.5);           // at its length
    EXPECT_EQ(time.delay(Vec3d(0.0, 3.0, 0.0)).d, 0.5);           // clamped beyond
    EXPECT_NEAR(time.delay(Vec3d(0.0, 0.0, 0.0)).d, 0.25, 1e-12); // half way: half the spread
    // Linear in the middle: the slope spread / (length (1 - 0.1)).
    EXPECT_NEAR(time.delay(Vec3d(0, 0.2, 0)).d - time.delay(Vec3d(0, -0.2, 0)).d, 0.4 * 0.5 / 0.9,
                1e-12);
    // C1: the gradient is continuous across the ends of the rounding (u = 0.1, 0.9) and equals
    // the central difference everywhere.
    for (double u : {0.0, 0.05, 0.1, 0.5, 0.9, 0.95, 1.0}) {
        const Vec3d x(0.1, -0.5 + u, 0.0);
        const Delay below = time.delay(x - Vec3d(0, 1e-9, 0)),
                    above = time.delay(x + Vec3d(0, 1e-9, 0));
        EXPECT_NEAR(below.gradient.y(), above.gradient.y(), 1e-6) << "u " << u;
        EXPECT_NEAR(time.delay(x).gradient.y(), delayDifference(time, x, 1e-6).y(), 1e-5)
            << "u " << u;
    }
    EXPECT_LE(time.delay(Vec3d(0, 0, 0)).gradient.length(), time.maxDelayGradient() + 1e-12);
}

TEST(LocalTime, EveryPlaceGoesFromTheSourceToTheTargetAndTauMatchesItsDerivatives)
{
    const LocalTime time(upward(0.4), {});
    std::mt19937 random(7);
    std::uniform_real_distribution<double> coordinate(-1.0, 1.0), unit(0.02, 0.98);
    for (int i = 0; i < 200; ++i) {
        const Vec3d x(coordinate(random), coordinate(random), coordinate(random));
        EXPECT_EQ(time.at(x, 0.0).tau, 0.0);
        EXPECT_EQ(time.at(x, 1.0).tau, 1.0);
        const double t = unit(random);
        const LocalTau tau = time.at(x, t);
        const double d = time.delay(x).d;
        EXPECT_NEAR(tau.tau, std::clamp((t - d) / 0.6, 0.0, 1.0), 1e-12);
        if (tau.tau <= 1e-6 || tau.tau >= 1.0 - 1e-6) continue; // the clamp's kinks
        const double h = 1e-6;
        EXPECT_NEAR(tau.dt, (time.at(x, t + h).tau - time.at(x, t - h).tau) / (2 * h), 1e-6);
        const Vec3d g = delayDifference(time, x, h) * (-1.0 / 0.6);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(tau.gradient[k], g[k], 1e-5);
    }
    // No spread: tau = t everywhere, d tau / d t = 1.
    const LocalTime now;
    EXPECT_FALSE(now.active());
    EXPECT_EQ(now.at(Vec3d(1, 2, 3), 0.3).tau, 0.3);
    EXPECT_EQ(now.at(Vec3d(1, 2, 3), 0.3).dt, 1.0);
}

TEST(LocalTime, ARegionOverridesTheSweepInsideAndFadesOverItsSoftness)
{
    constexpr double kVoxel = 0.01, kRadius = 0.3, kSoftness = 0.1;
    const auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(kRadius), openvdb::Vec3f(0.0f, 0.5, 0.0f), float(kVoxel), 15.0f);
    const LocalTime time(upward(0.5), {TimingRegion{sphere, 0.0, kSoftness}});
    const LocalTime sweep(upward(0.5), {});
    EXPECT_EQ(time.delay(Vec3d(0.0, 0.5, 0.0)).d, 0.0);           // the centre: the region's
    EXPECT_NEAR(time.delay(Vec3d(0.0, 0.5, 0.28)).d, 0.0, 1e-12); // inside near its surface
    // Beyond the softness: the sweep's own delay.
    const Vec3d beyond(0.0, 0.5, kRadius + kSoftness + 0.02);
    EXPECT_NEAR(time.delay(beyond).d, sweep.delay(beyond).d, 1e-12);
    // Half way through the softness: smoothstep's half, between the two.
    const Vec3d half(0.0, 0.5, kRadius + 0.5 * kSoftness);
    EXPECT_NEAR(time.delay(half).d, 0.5 * sweep.delay(half).d, 0.02);
    // The gradient is the delay's own derivative (the level set is read through its quadratic
    // B-spline: C1), against central differences over a thousandth of a voxel, also across the
    // voxels' faces, and continuous there.
    for (double r = kRadius + 0.001; r < kRadius + kSoftness; r += 0.0025) {
        const Vec3d x(0.0512, 0.5037, r);
        const Vec3d g = time.delay(x).gradient, dg = delayDifference(time, x, 1e-5);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], dg[k], 1e-4) << "r " << r << " axis " << k;
        EXPECT_LE(g.length(), time.maxDelayGradient());
    }
    const double face = kRadius + 0.5 * kSoftness + 0.5 * kVoxel; // between two voxels' samples
    const Vec3d below = time.delay(Vec3d(0.0, 0.5, face - 1e-9)).gradient,
                above = time.delay(Vec3d(0.0, 0.5, face + 1e-9)).gradient;
    EXPECT_NEAR((below - above).length(), 0.0, 1e-6);
    EXPECT_THROW(LocalTime(upward(1.0), {}), std::invalid_argument);
    EXPECT_THROW(LocalTime(upward(0.5), {TimingRegion{sphere, 0.6, 0.1}}), std::invalid_argument);
    EXPECT_THROW(LocalTime(upward(0.5), {TimingRegion{sphere, 0.0, 0.5}}), // beyond its band
                 std::invalid_argument);
}
