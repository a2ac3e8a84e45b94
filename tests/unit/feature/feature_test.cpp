// Feature elements: distances per type, local coordinates, interpolation over t.
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;

TEST(Feature, DistancePerType)
{
    Feature f;
    f.scale = Vec3d(2, 1, 0.5);
    f.type = FeatureType::Point;
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(3, 4, 0)), 5.0);
    f.type = FeatureType::Segment; // x in [-1, 1]
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(0.5, 3, 4)), 5.0);
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(4, 0, 0)), 3.0);
    f.type = FeatureType::Rectangle; // x in [-1, 1], y in [-0.5, 0.5], z = 0
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(0.5, 0.25, -2)), 2.0);
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(4, 4.5, 0)), 5.0);
    f.type = FeatureType::Box; // z in [-0.25, 0.25] too
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(0.5, 0.25, 0.1)), 0.0);
    EXPECT_DOUBLE_EQ(f.distance(Vec3d(0, 0, 2.25)), 2.0);
}

TEST(Feature, LocalCoordinatesRoundTrip)
{
    Feature f = Feature::fromElement(
        element(Vec3d(1, 2, 3), Vec3d(0, 0, 1), Vec3d(0, 1, 0), Vec3d(2, 3, 4)), FeatureType::Box);
    const Vec3d p(0.3, -1.2, 7.0);
    EXPECT_NEAR((f.fromLocal(f.toLocal(p)) - p).length(), 0.0, 1e-12);
    EXPECT_NEAR((f.toLocal(Vec3d(1, 2, 5)) - Vec3d(1.0, 0.0, 0.0)).length(), 0.0,
                1e-12); // 2 along x = +z
}

TEST(Feature, SlerpTakesTheShorterArc)
{
    const Feature a = Feature::fromElement(element(Vec3d(0.0)), FeatureType::Box);
    // b is rotated 90 degrees about z: x -> y.
    const Feature b = Feature::fromElement(
        element(Vec3d(2, 0, 0), Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(3.0)), FeatureType::Box);
    const Feature m = interpolate(a, b, 0.5);
    EXPECT_NEAR((m.x - Vec3d(std::sqrt(0.5), std::sqrt(0.5), 0)).length(), 0.0, 1e-9);
    EXPECT_NEAR((m.z - Vec3d(0, 0, 1)).length(), 0.0, 1e-9);
    EXPECT_NEAR((m.origin - Vec3d(1, 0, 0)).length(), 0.0, 1e-12);
    EXPECT_NEAR((m.scale - Vec3d(2.0)).length(), 0.0, 1e-12);
    // 270 degrees one way is 90 the other: the interpolant turns by -45 degrees, not +135.
    const Feature c = Feature::fromElement(element(Vec3d(0.0), Vec3d(0, -1, 0), Vec3d(1, 0, 0)),
                                           FeatureType::Box);
    const Feature h = interpolate(a, c, 0.5);
    EXPECT_NEAR((h.x - Vec3d(std::sqrt(0.5), -std::sqrt(0.5), 0)).length(), 0.0, 1e-9);
    EXPECT_NEAR(interpolate(a, c, 0.0).x.x(), 1.0, 1e-12);
    EXPECT_NEAR((interpolate(a, c, 1.0).x - Vec3d(0, -1, 0)).length(), 0.0, 1e-12);
}

TEST(Feature, RotationQuaternionMatchesOpenVdbsAndAcceptsFramesAFewUlpsOff)
{
    std::mt19937 random(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int refused = 0;
    for (int i = 0; i < 20000; ++i) {
        // Random frames, including ones near the half-turns where the trace is negative.
        const Vec3d axis = Vec3d(u(random), u(random), u(random)).unit();
        const double angle =
            i % 4 == 0 ? M_PI * (1.0 - 1e-3 * std::abs(u(random))) : M_PI * u(random);
        const Vec3d x = rotate(Vec3d(1, 0, 0), axis, angle),
                    y = rotate(Vec3d(0, 1, 0), axis, angle);
        const Vec3d z = x.cross(y);
        const openvdb::math::Quatd q = rotationQuaternion(x, y, z);
        EXPECT_NEAR(std::sqrt(q.dot(q)), 1.0, 1e-14);
        // The quaternion gives the frame back, in the convention rotation<Mat3> reads it.
        const auto m = openvdb::math::rotation<openvdb::math::Mat3d>(q);
        EXPECT_NEAR((m.row(0) - x).length() + (m.row(1) - y).length() + (m.row(2) - z).length(),
                    0.0, 1e-12);
        try {
            const openvdb::math::Quatd reference(openvdb::math::Mat3d(x, y, z, /*rows=*/true));
            EXPECT_NEAR(std::abs(q.dot(reference)), 1.0, 1e-12); // q or -q: one rotation
        } catch (const openvdb::ArithmeticError&) {
            ++refused; // a few ulps off: OpenVDB refuses it, interpolate() must not
        }
    }
    std::printf("frames OpenVDB's Quat refuses: %d of 20000\n", refused);
    // A frame a few ulps off orthonormal, which OpenVDB's constructor refuses, still interpolates.
    const Feature a = Feature::fromElement(element(Vec3d(0.0)), FeatureType::Box);
    Feature b = a;
    b.x = Vec3d(1.0 + 3e-15, 0, 0); // 13 ulps long
    EXPECT_THROW(openvdb::math::Quatd(openvdb::math::Mat3d(b.x, b.y, b.z, true)),
                 openvdb::ArithmeticError);
    const Feature m = interpolate(a, b, 0.5);
    EXPECT_NEAR((m.x - Vec3d(1, 0, 0)).length(), 0.0, 1e-12);
}
