// The exact inverse warp (Warp.h): identity, one pair affine, inverse-square weights, degenerate
// inputs.
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;

TEST(InverseWarp, NoPairsIsTheIdentity)
{
    const InverseWarp w({}, WarpSpec{}, 0.3);
    Vec3d s, t;
    w.map(Vec3d(1, 2, 3), s, t);
    EXPECT_EQ(s, Vec3d(1, 2, 3));
    EXPECT_EQ(t, Vec3d(1, 2, 3));
}

TEST(InverseWarp, OnePairIsAnAffineMap)
{
    // Source: a box at the origin along x. Target: scaled by 2 and rotated 90 degrees about z.
    const auto p = pair(FeatureType::Box, element(Vec3d(0.0)),
                        element(Vec3d(5, 0, 0), Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(2.0)));
    const InverseWarp w({p}, WarpSpec{}, 1.0);
    Vec3d s, t;
    w.map(Vec3d(5, 2, 0), s,
          t); // at t = 1 the output is target space: the target side is the identity
    EXPECT_NEAR((t - Vec3d(5, 2, 0)).length(), 0.0, 1e-12);
    EXPECT_NEAR((s - Vec3d(1, 0, 0)).length(), 0.0,
                1e-12); // 2 along target x (= +y) is 1 along source x
    const InverseWarp w0({p}, WarpSpec{}, 0.0);
    w0.map(Vec3d(0.5, 0.5, 0.5), s, t);
    EXPECT_NEAR((s - Vec3d(0.5)).length(), 0.0, 1e-12);
}

TEST(InverseWarp, WeightsFollowTheInverseSquareLaw)
{
    // Two point pairs translating by +1 and -1 in x; halfway between them the two cancel.
    const auto a = pair(FeatureType::Point, element(Vec3d(-1, 0, 0)), element(Vec3d(0, 0, 0)));
    const auto b = pair(FeatureType::Point, element(Vec3d(1, 0, 0)), element(Vec3d(0, 0, 0)));
    WarpSpec spec;
    spec.epsilon = 0.0;
    const InverseWarp w({a, b}, spec, 1.0);
    Vec3d s, t;
    w.map(Vec3d(0, 3, 0), s, t);
    EXPECT_NEAR(s.x(), 0.0, 1e-12);
    // At distance 1 from pair a's interpolated element and 3 from b's... both are at the origin at
    // t = 1, so move off-centre: weights 1/d^2 are equal; use t = 0.5 with elements at -0.5 and
    // 0.5.
    const InverseWarp h({a, b}, spec, 0.5);
    h.map(Vec3d(1.5, 0, 0), s, t); // d_a = 2, d_b = 1: w = 1/4 and 1
    // pair a maps p -> p - 0.5, pair b maps p -> p + 0.5 on the source side.
    EXPECT_NEAR(s.x(), (0.25 * 1.0 + 1.0 * 2.0) / 1.25, 1e-12);
}

TEST(InverseWarp, DegenerateInputsStayFinite)
{
    WarpSpec spec;
    spec.epsilon = 0.0;
    // Coincident features with different targets, and a point exactly on them with epsilon = 0.
    const auto a = pair(FeatureType::Segment, element(Vec3d(0.0)), element(Vec3d(1, 0, 0)));
    const auto b = pair(FeatureType::Segment, element(Vec3d(0.0)), element(Vec3d(-1, 0, 0)));
    const auto c = pair(FeatureType::Point, element(Vec3d(2, 2, 2)), element(Vec3d(2, 2, 3)));
    for (double t : {0.0, 0.5, 1.0}) {
        const InverseWarp w({a, b, c}, spec, t);
        for (const Vec3d& p :
             {Vec3d(0.0), Vec3d(0.2, 0, 0), Vec3d(2, 2, 2 + t), Vec3d(1e6, -1e6, 3)}) {
            Vec3d s, d;
            w.map(p, s, d);
            for (int k = 0; k < 3; ++k) {
                EXPECT_TRUE(std::isfinite(s[k]) && std::isfinite(d[k])) << p << " at t " << t;
            }
        }
    }
}
