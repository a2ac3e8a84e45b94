// The surface stage: the identity correspondence, the straight line and the as-rigid-as-possible
// in-betweens (Xu et al. 2005), each against a closed form: a tube bent by 120 degrees keeps its
// volume (Pappus: pi r^2 L whatever the bend) where the straight line loses it.
#include <volmorph/SurfaceMorph.h>

#include "support/SurfaceShapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace volmorph {
namespace {
using test::bent;
using test::tube;

constexpr double kPi = 3.14159265358979323846;

template <typename P>
double volume(const std::vector<P>& points, const std::vector<Vec3I>& tris)
{
    double v = 0.0;
    for (const Vec3I& t : tris)
        v += Vec3d(points[t[0]]).dot(Vec3d(points[t[1]]).cross(Vec3d(points[t[2]])));
    return v / 6.0;
}

SurfaceSpec spec(SurfaceInterpolation interpolation)
{
    SurfaceSpec s;
    s.correspondence = Correspondence::Identity;
    s.interpolation = interpolation;
    s.where = SourceLocation{"scene.toml", 3, 1};
    return s;
}

constexpr double kLength = 4.0, kRadius = 0.3, kBend = 2.0 * kPi / 3.0;

TEST(SurfaceMorph, LinearIsTheStraightLineExactly)
{
    const Mesh a = tube(21, 16, kLength, kRadius), b = bent(a, kLength, kBend);
    const SurfaceMorpher morph(a, b, spec(SurfaceInterpolation::Linear));
    EXPECT_EQ(morph.correspondence(), Correspondence::Identity);
    for (double tau : {0.0, 0.3, 0.5, 1.0}) {
        const SurfaceFrame f = morph.frame(tau, tau);
        ASSERT_EQ(f.points.size(), a.points.size());
        EXPECT_EQ(f.triangles, a.triangles);
        for (size_t i = 0; i < a.points.size(); ++i) {
            const Vec3d p(a.points[i]), q(b.points[i]);
            const Vec3d expected = (1.0 - tau) * p + tau * q;
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(f.points[i][c], expected[c], 1e-12);
                EXPECT_NEAR(f.velocity[i][c], (q - p)[c], 1e-12);
            }
        }
    }
}

TEST(SurfaceMorph, RigidInBetweensKeepTheBentTubesVolumeWhereTheLineLosesIt)
{
    const Mesh a = tube(41, 24, kLength, kRadius), b = bent(a, kLength, kBend);
    const double va = volume(a.points, a.triangles), vb = volume(b.points, b.triangles);
    ASSERT_NEAR(vb / va, 1.0, 0.01); // Pappus: bending keeps the volume
    const SurfaceMorpher rigid(a, b, spec(SurfaceInterpolation::Arap));
    const SurfaceMorpher line(a, b, spec(SurfaceInterpolation::Linear));
    const SurfaceFrame fr = rigid.frame(0.5, 0.5), fl = line.frame(0.5, 0.5);
    const double ends = 0.5 * (va + vb);
    const double vr = volume(fr.points, fr.triangles), vl = volume(fl.points, fl.triangles);
    EXPECT_NEAR(vr / ends, 1.0, 0.03) << "arap " << vr << ", ends " << ends;
    EXPECT_LT(vl / ends, 0.92) << "linear " << vl << ", ends " << ends;

    // Every edge half-way is within 2% of the mean of its two end lengths.
    double worst = 0.0;
    for (const Vec3I& t : a.triangles)
        for (int c = 0; c < 3; ++c) {
            const uint32_t i = t[c], j = t[(c + 1) % 3];
            const double la = (Vec3d(a.points[i]) - Vec3d(a.points[j])).length();
            const double lb = (Vec3d(b.points[i]) - Vec3d(b.points[j])).length();
            const double lr = (fr.points[i] - fr.points[j]).length();
            worst = std::max(worst, std::abs(lr / (0.5 * (la + lb)) - 1.0));
        }
    EXPECT_LT(worst, 0.02);
    std::printf("half-way volume over the ends': arap %.4f, linear %.4f; arap's worst edge %.4f\n",
                vr / ends, vl / ends, worst);
}

TEST(SurfaceMorph, RigidEndsAreTheInputs)
{
    const Mesh a = tube(21, 16, kLength, kRadius), b = bent(a, kLength, kBend);
    const SurfaceMorpher rigid(a, b, spec(SurfaceInterpolation::Arap));
    const double diagonal = std::sqrt(kLength * kLength + 8.0 * kRadius * kRadius);
    for (const auto& [tau, side] : {std::pair{0.0, &a}, std::pair{1.0, &b}}) {
        const SurfaceFrame f = rigid.frame(tau, tau);
        for (size_t i = 0; i < f.points.size(); ++i)
            EXPECT_LT((f.points[i] - Vec3d(side->points[i])).length(), 1e-9 * diagonal)
                << "tau " << tau << " vertex " << i;
    }
}

TEST(SurfaceMorph, RigidVelocityIsTheDerivativeOfThePositions)
{
    const Mesh a = tube(21, 16, kLength, kRadius), b = bent(a, kLength, kBend);
    const SurfaceMorpher rigid(a, b, spec(SurfaceInterpolation::Arap));
    const double h = 1e-5;
    for (double tau : {0.2, 0.5, 0.9}) {
        const SurfaceFrame f = rigid.frame(tau, tau);
        const SurfaceFrame lo = rigid.frame(tau - h, tau), hi = rigid.frame(tau + h, tau);
        for (size_t i = 0; i < f.points.size(); ++i) {
            const Vec3d difference = (hi.points[i] - lo.points[i]) / (2.0 * h);
            EXPECT_LT((f.velocity[i] - difference).length(), 0.01 * difference.length() + 1e-9)
                << "tau " << tau << " vertex " << i;
        }
    }
}

TEST(SurfaceMorph, ColoursAtTheEndsAreTheInputs)
{
    Mesh a = tube(5, 8, kLength, kRadius), b = bent(a, kLength, kBend);
    for (size_t i = 0; i < a.points.size(); ++i)
        a.colors.emplace_back(float(i % 3) / 2.0f, 0.25f, float(i % 5) / 4.0f);
    const SurfaceMorpher morph(a, b, spec(SurfaceInterpolation::Arap));
    EXPECT_EQ(morph.frame(0.0, 0.0).colors, a.colors);
    // The target had none: grey.
    EXPECT_EQ(morph.frame(1.0, 1.0).colors, std::vector<Vec3f>(a.points.size(), Vec3f(0.8f)));
    const SurfaceFrame half = morph.frame(0.5, 0.5);
    EXPECT_NEAR(half.colors[1].x(), 0.5 * (0.5 + 0.8), 1e-6);
}

TEST(SurfaceMorph, TwoPiecesEachFollowTheirOwnCentre)
{
    Mesh a = tube(9, 8, kLength, kRadius);
    const Mesh first = a;
    for (const Vec3f& p : first.points) a.points.push_back(p + Vec3f(0.0f, 0.0f, 2.0f));
    const uint32_t n = uint32_t(first.points.size());
    for (const Vec3I& t : first.triangles) a.triangles.emplace_back(t[0] + n, t[1] + n, t[2] + n);
    analyzeTopology(a);
    Mesh b = bent(a, kLength, kBend);
    const SurfaceMorpher rigid(a, b, spec(SurfaceInterpolation::Arap));
    for (double tau : {0.0, 1.0}) {
        const SurfaceFrame f = rigid.frame(tau, tau);
        const Mesh& side = tau == 0.0 ? a : b;
        for (size_t i = 0; i < f.points.size(); ++i)
            EXPECT_LT((f.points[i] - Vec3d(side.points[i])).length(), 1e-9);
    }
}

TEST(SurfaceMorph, IdentityRefusesDifferentConnectivityNamingTheFiles)
{
    const Mesh a = tube(9, 8, kLength, kRadius), b = tube(9, 10, kLength, kRadius);
    try {
        SurfaceMorpher(a, b, spec(SurfaceInterpolation::Arap));
        FAIL() << "no error";
    } catch (const UserError& e) {
        const std::string text = e.what();
        EXPECT_NE(text.find("scene.toml:3:1"), std::string::npos) << text;
        EXPECT_NE(text.find("tube.obj (74 vertices"), std::string::npos) << text;
        EXPECT_NE(text.find("(92 vertices"), std::string::npos) << text;
    }
    Mesh c = a;
    std::swap(c.triangles[3][0], c.triangles[3][1]);
    EXPECT_THROW(SurfaceMorpher(a, c, spec(SurfaceInterpolation::Linear)), UserError);
}

TEST(SurfaceMorph, RefusesNonManifoldEdges)
{
    Mesh a = tube(5, 8, kLength, kRadius);
    const Vec3I extra(a.triangles[0][0], a.triangles[0][1], uint32_t(a.points.size() - 1));
    a.triangles.push_back(extra);
    a.triangles.push_back(Vec3I(extra[1], extra[0], uint32_t(a.points.size() - 2)));
    analyzeTopology(a);
    ASSERT_GT(a.report.nonManifoldEdges, 0u);
    try {
        SurfaceMorpher(a, a, spec(SurfaceInterpolation::Arap));
        FAIL() << "no error";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("non-manifold"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace volmorph
