// The exact warp's derivatives and velocity (InverseWarp::derivatives): against central differences
// of the warp itself at random pairs of every type and both weightings, and against closed forms (a
// translating point pair, a box pair turning 90 degrees, a pair scaling).
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;
using Mat3d = openvdb::math::Mat3d;

namespace {

/// The warp's derivatives by central differences of map() (step h in p' and in t).
struct Differenced {
    InverseWarp::Derivatives source, target;
};
Differenced differenced(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec, double t,
                        const Vec3d& p, double h)
{
    Differenced out;
    const InverseWarp w(pairs, spec, t);
    for (int j = 0; j < 3; ++j) {
        Vec3d e(0.0);
        e[j] = h;
        Vec3d s0, t0, s1, t1;
        w.map(p - e, s0, t0);
        w.map(p + e, s1, t1);
        for (int i = 0; i < 3; ++i) {
            out.source.jacobian(i, j) = (s1[i] - s0[i]) / (2 * h);
            out.target.jacobian(i, j) = (t1[i] - t0[i]) / (2 * h);
        }
    }
    Vec3d s0, t0, s1, t1;
    InverseWarp(pairs, spec, t - h).map(p, s0, t0);
    InverseWarp(pairs, spec, t + h).map(p, s1, t1);
    out.source.rate = (s1 - s0) / (2 * h);
    out.target.rate = (t1 - t0) / (2 * h);
    return out;
}

Vec3d velocityAt(const InverseWarp& w, const Vec3d& p, bool source = true)
{
    InverseWarp::Derivatives ds, dt;
    w.derivatives(p, ds, dt);
    Vec3d v;
    EXPECT_TRUE(InverseWarp::velocity(source ? ds : dt, v));
    return v;
}

} // namespace

TEST(WarpVelocity, AngularVelocityTurnsTheInterpolatedFrame)
{
    // d(axis)/dt = omega x axis along interpolate()'s slerp, for turns up to nearly half a turn.
    std::mt19937 random(7);
    for (int trial = 0; trial < 40; ++trial) {
        const auto p = randomPairs(random, 1, 10.0)[0];
        const Feature a = Feature::fromElement(p.source, p.type);
        Feature b = Feature::fromElement(p.target, p.type);
        if (trial % 4 == 3) { // 179 degrees about z
            const double angle = 179.0 * M_PI / 180.0;
            b.x = rotate(a.x, Vec3d(0, 0, 1), angle);
            b.y = rotate(a.y, Vec3d(0, 0, 1), angle);
            b.z = b.x.cross(b.y);
        }
        const Vec3d omega = angularVelocity(a, b);
        for (double t : {0.2, 0.5, 0.8}) {
            const double h = 1e-6;
            const Feature f = interpolate(a, b, t), f0 = interpolate(a, b, t - h),
                          f1 = interpolate(a, b, t + h);
            EXPECT_NEAR(((f1.x - f0.x) / (2 * h) - omega.cross(f.x)).length(), 0.0, 1e-6);
            EXPECT_NEAR(((f1.y - f0.y) / (2 * h) - omega.cross(f.y)).length(), 0.0, 1e-6);
        }
    }
}

TEST(WarpVelocity, DerivativesAreTheWarpsOwn)
{
    // Random pairs of all four types, inverse-square and Beier-Neely weights (with p > 0, so the
    // element's length changes the weights too), at random points: the analytic J and dW/dt
    // equal the central differences of map() to within their truncation error.
    std::mt19937 random(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 30; ++trial) {
        const auto pairs = randomPairs(random, 1 + trial % 6, 20.0);
        WarpSpec spec;
        if (trial % 2) {
            spec.weighting = Weighting::BeierNeely;
            spec.p = 0.5;
        }
        for (int k = 0; k < 20; ++k) {
            const Vec3d p(u(random) * 30 - 5, u(random) * 30 - 5, u(random) * 30 - 5);
            const double t = 0.05 + 0.9 * u(random);
            InverseWarp::Derivatives s, g;
            InverseWarp(pairs, spec, t).derivatives(p, s, g);
            const Differenced d = differenced(pairs, spec, t, p, 1e-5);
            EXPECT_LT(relativeError(s, d.source), 1e-5) << "trial " << trial << " at " << p;
            EXPECT_LT(relativeError(g, d.target), 1e-5) << "trial " << trial << " at " << p;
        }
    }
}

TEST(WarpVelocity, APointPairTranslatingByDMovesEverythingByD)
{
    // One pair: W_S(p', t) = p' - t d, so v = d per unit t everywhere, on both sides.
    const Vec3d d(3.0, -1.0, 0.5);
    const auto p = pair(FeatureType::Point, element(Vec3d(1, 2, 3)), element(Vec3d(1, 2, 3) + d));
    for (double t : {0.0, 0.3, 1.0}) {
        const InverseWarp w({p}, WarpSpec{}, t);
        for (const Vec3d& x : {Vec3d(0.0), Vec3d(5, -2, 7)}) {
            EXPECT_NEAR((velocityAt(w, x) - d).length(), 0.0, 1e-12);
            EXPECT_NEAR((velocityAt(w, x, false) - d).length(), 0.0, 1e-12);
        }
    }
}

TEST(WarpVelocity, ABoxTurning90DegreesMovesAsOmegaCrossR)
{
    // About z through (1, 1, 0), a quarter turn over the morph: omega = pi / 2 per unit t.
    const Vec3d c(1, 1, 0);
    const auto p = pair(FeatureType::Box, element(c, Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(2.0)),
                        element(c, Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(2.0)));
    const Vec3d omega(0, 0, M_PI / 2);
    for (double t : {0.1, 0.5, 0.9}) {
        const InverseWarp w({p}, WarpSpec{}, t);
        for (const Vec3d& x : {Vec3d(2, 1, 0), Vec3d(0.5, 3, 2), Vec3d(-4, 0, 1)})
            EXPECT_NEAR((velocityAt(w, x) - omega.cross(x - c)).length(), 0.0, 1e-9) << x;
    }
}

TEST(WarpVelocity, APairScalingMovesAsRTimesTheScaleRate)
{
    // Scales 1 -> 3 about (0, 0, 2): s(t) = 1 + 2t, v = r s'/s.
    const Vec3d c(0, 0, 2);
    const auto p =
        pair(FeatureType::Segment, element(c, Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(1.0)),
             element(c, Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(3.0)));
    for (double t : {0.0, 0.5, 1.0}) {
        const InverseWarp w({p}, WarpSpec{}, t);
        for (const Vec3d& x : {Vec3d(0.2, 0, 2), Vec3d(3, -1, 5)})
            EXPECT_NEAR((velocityAt(w, x) - (x - c) * (2.0 / (1.0 + 2.0 * t))).length(), 0.0, 1e-9)
                << x;
    }
}

TEST(WarpVelocity, NoPairsIsStill)
{
    const InverseWarp w({}, WarpSpec{}, 0.4);
    EXPECT_EQ(velocityAt(w, Vec3d(1, 2, 3)), Vec3d(0.0));
}
