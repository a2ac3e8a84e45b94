// The spherical parameterization (surface/SphereParam.h) and the `sphere` correspondence's merge
// (surface/SphereMerge.h), against what is independent of them: the exact orientation predicate and
// the sphere's area 4 pi (one-to-one), a round sphere's own map (its directions from the centre,
// up to a turn), the inputs' surfaces, volumes and areas (checkMerge), and a shape moved by a
// known smooth map and triangulated anew, which the correspondence should find again.
#include "surface/SphereMerge.h"
#include "surface/SphereParam.h"
#include "surface/SpherePredicates.h"
#include "surface/SphereStretch.h"
#include "surface/StarKernel.h"

#include "support/MergeChecks.h"
#include "support/OpenMeshes.h"
#include "support/SurfaceShapes.h"

#include <volmorph/SurfaceMorph.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <tuple>

namespace volmorph::detail {
namespace {

using test::checkMerge;
using test::pointsOf;

const SourceLocation kWhere{"scene.toml", 7, 18};

/// A C: a closed tube bent through 300 degrees (no point sees all of it).
Mesh cShape(int rings, int around)
{
    Mesh m = test::bent(test::tube(rings, around, 4.0, 0.3), 4.0, 1.7 * M_PI);
    m.file = "c.obj";
    return m;
}

void expectOneToOne(const Mesh& mesh, const SphereMap& map)
{
    size_t turned = 0;
    double area = 0.0;
    for (const Vec3I& t : mesh.triangles) {
        const Vec3d &p = map.directions[t[0]], &q = map.directions[t[1]], &r = map.directions[t[2]];
        turned += orientation(toGrid(p), toGrid(q), toGrid(r)) <= 0;
        area += sphericalArea(p, q, r);
    }
    EXPECT_EQ(turned, 0u) << mesh.file;
    EXPECT_NEAR(area, 4.0 * M_PI, 1e-9) << mesh.file;
    EXPECT_GT(map.stretchEfficiency, 0.0);
    EXPECT_LE(map.stretchEfficiency, 1.0);
}

TEST(SphereParam, OneToOneOnShapesThatAreNotStarShaped)
{
    const Mesh bumpy = test::radialSphere(
        14, 20, Vec3d(0.3, 0.0, 0.0),
        [](const Vec3d& d) { return 1.0 + 0.45 * std::sin(5.0 * d.x()) * std::cos(4.0 * d.z()); },
        "bumpy.obj");
    for (const Mesh& m : {cShape(31, 12), bumpy, test::cube(1.0, Vec3d(0.0))}) {
        const SphereMap map = sphericalMap(pointsOf(m), m.triangles);
        expectOneToOne(m, map);
        EXPECT_EQ(map.collapses, m.points.size() - 4);
    }
}

TEST(SphereParam, ARoundSphereMapsOntoItselfUpToATurn)
{
    const Vec3d centre(1.0, -0.5, 0.25);
    const Mesh ball = test::radialSphere(
        12, 24, centre, [](const Vec3d&) { return 2.0; }, "ball.obj");
    const SphereMap map = sphericalMap(pointsOf(ball), ball.triangles);
    expectOneToOne(ball, map);
    EXPECT_GT(map.stretchEfficiency, 0.95);
    // The best turn of the directions from the centre onto the map's (Kabsch), then the largest
    // angle between the two.
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    std::vector<Vec3d> from;
    for (const Vec3f& p : ball.points) {
        from.push_back((Vec3d(p) - centre).unitSafe());
        const Vec3d& to = map.directions[from.size() - 1];
        h += Eigen::Vector3d(from.back().x(), from.back().y(), from.back().z()) *
             Eigen::Vector3d(to.x(), to.y(), to.z()).transpose();
    }
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d turn = svd.matrixV() * svd.matrixU().transpose();
    ASSERT_GT(turn.determinant(), 0.0);
    double worst = 0.0;
    for (size_t v = 0; v < from.size(); ++v) {
        const Eigen::Vector3d a = turn * Eigen::Vector3d(from[v].x(), from[v].y(), from[v].z());
        const Vec3d& b = map.directions[v];
        worst =
            std::max(worst, std::acos(std::min(1.0, a.dot(Eigen::Vector3d(b.x(), b.y(), b.z())))));
    }
    EXPECT_LT(worst, 0.05) << "radians";
}

TEST(SphereMerge, TheMergedMeshLiesOnBothInputs)
{
    const Mesh a = cShape(31, 12);
    const Mesh b = test::radialSphere(
        9, 14, Vec3d(0.5, 1.0, 0.0), [](const Vec3d&) { return 1.1; }, "ball.obj");
    const Corresponded c = sphereMerge(a, b, {}, kWhere);
    EXPECT_EQ(c.used, Correspondence::Sphere);
    ASSERT_TRUE(c.stretch);
    checkMerge(a, b, c);
    // auto: not star-shaped, so the spherical map; the in-betweens start and end on the inputs.
    SurfaceSpec automatic;
    const SurfaceMorpher m(a, b, automatic);
    EXPECT_EQ(m.correspondence(), Correspondence::Sphere);
    test::expectEndsOnSides(m, c);
}

/// `m` with texture coordinates per triangle corner: `f` of the corner's point plus an offset of
/// `step` x (triangle index mod 3), islands as an atlas's seams make them.
Mesh withUVs(Mesh m, const std::function<Vec2d(const Vec3d&)>& f, double step)
{
    m.uvs.clear();
    for (size_t j = 0; j < m.triangles.size(); ++j)
        for (int c = 0; c < 3; ++c)
            m.uvs.emplace_back(f(Vec3d(m.points[m.triangles[j][c]])) + Vec2d(step * double(j % 3)));
    return m;
}

TEST(SphereMerge, TextureCoordinatesFollowEachSideAcrossItsSeams)
{
    const auto fa = [](const Vec3d& p) { return Vec2d(p.x(), p.y()); };
    const auto fb = [](const Vec3d& p) { return Vec2d(p.y() + p.z(), p.x()); };
    const Mesh a = withUVs(cShape(31, 12), fa, 10.0);
    const Mesh b =
        withUVs(test::radialSphere(
                    9, 14, Vec3d(0.5, 1.0, 0.0), [](const Vec3d&) { return 1.1; }, "ball.obj"),
                fb, 10.0);
    const Corresponded c = sphereMerge(a, b, {}, kWhere);
    ASSERT_EQ(c.sourceUVs.size(), 3 * c.triangles.size());
    ASSERT_EQ(c.targetUVs.size(), 3 * c.triangles.size());
    // Each corner: the side's linear function at the vertex's place there, plus the island offset
    // of the side's triangle the merged triangle lies in, the same at its three corners.
    double worst = 0.0;
    for (size_t j = 0; j < c.triangles.size(); ++j)
        for (const auto& [uvs, points, f] :
             {std::tuple{&c.sourceUVs, &c.source, +fa}, std::tuple{&c.targetUVs, &c.target, +fb}}) {
            const Vec2d island = (*uvs)[3 * j] - f((*points)[c.triangles[j][0]]);
            EXPECT_NEAR(std::remainder(island.x(), 10.0), 0.0, 1e-6);
            for (size_t k = 0; k < 3; ++k) {
                const Vec2d want = f((*points)[c.triangles[j][k]]) + island;
                worst = std::max(worst, ((*uvs)[3 * j + k] - want).length());
            }
        }
    EXPECT_LT(worst, 1e-5); // the inputs' coordinates are floats up to 22: 2e-6 apart there
    // The frames: the source's at tau 0, the target's at 1, both ends in every frame.
    const SurfaceMorpher m(a, b, SurfaceSpec{});
    const SurfaceFrame f0 = m.frame(0.0, 0.0), f1 = m.frame(1.0, 1.0), half = m.frame(0.5, 0.5);
    ASSERT_EQ(f0.uvs.size(), c.sourceUVs.size());
    for (size_t k = 0; k < c.sourceUVs.size(); ++k) {
        EXPECT_EQ(f0.uvs[k], Vec2f(c.sourceUVs[k]));
        EXPECT_EQ(f1.uvs[k], Vec2f(c.targetUVs[k]));
        EXPECT_EQ(half.sourceUVs[k], Vec2f(c.sourceUVs[k]));
        EXPECT_EQ(half.targetUVs[k], Vec2f(c.targetUVs[k]));
    }
}

/// A smooth map of space, one-to-one on the C: a stretch, a shear and a swell.
Vec3d smoothMap(const Vec3d& p)
{
    return Vec3d(1.15 * p.x() + 0.08 * p.y() * p.y(), p.y() + 0.12 * std::sin(1.3 * p.x()),
                 0.9 * p.z() * (1.0 + 0.1 * p.y()));
}

/// The mean distance, over the merged vertices, between where a merge of `a` into f(`b`) puts
/// each vertex at t = 1 and f of where it is at t = 0, as a fraction of f(b)'s diagonal: `a` and
/// `b` the same shape triangulated otherwise, f = smoothMap, five landmark pairs at the centres of
/// `a`'s triangles `marks` and their images.
double knownMapError(const Mesh& a, Mesh b, const std::vector<size_t>& marks)
{
    for (Vec3f& p : b.points) p = Vec3f(smoothMap(Vec3d(p)));
    b.file = "moved.obj";
    std::vector<SurfaceLandmark> landmarks;
    for (size_t j : marks) {
        const Vec3I& t = a.triangles[j];
        const Vec3d p =
            (Vec3d(a.points[t[0]]) + Vec3d(a.points[t[1]]) + Vec3d(a.points[t[2]])) / 3.0;
        landmarks.push_back({p, smoothMap(p), {"scene.toml", int(10 + landmarks.size()), 1}});
    }
    const Corresponded c = sphereMerge(a, b, landmarks, kWhere);
    for (const SurfaceLandmark& l : landmarks) EXPECT_GE(test::meeting(c, a, b, l), 0);
    const auto [lo, hi] = b.bounds();
    double sum = 0.0;
    for (size_t v = 0; v < c.source.size(); ++v)
        sum += (c.target[v] - smoothMap(c.source[v])).length();
    return sum / double(c.source.size()) / (hi - lo).length();
}

TEST(SphereMerge, FindsAKnownSmoothMapBetweenTwoTriangulationsOfAShape)
{
    // A banana (a thick tube bent through 180 degrees: no point sees all of it).
    const auto banana = [](int rings, int around) {
        return test::bent(test::tube(rings, around, 3.0, 0.6), 3.0, M_PI);
    };
    ASSERT_LT(deepestKernelPoint(pointsOf(banana(25, 16)), banana(25, 16).triangles).margin, 0.0);
    const double error = knownMapError(banana(25, 16), banana(19, 21), {0, 100, 300, 500, 700});
    EXPECT_LT(error, 0.02) << "of the diagonal";
    RecordProperty("banana_mean_error_of_diagonal", std::to_string(error));
    // A C (a thin tube through 300 degrees, 13 times as long as it is thick) stretches much more
    // on the sphere, and two of its maps agree less: 3.3% when this was written (BENCHMARKS.md);
    // held to twice that so a regression shows.
    const double c = knownMapError(cShape(31, 12), cShape(23, 17), {0, 150, 300, 450, 600});
    EXPECT_LT(c, 0.062) << "of the diagonal";
    RecordProperty("c_mean_error_of_diagonal", std::to_string(c));
}

std::string refusal(const Mesh& a, const Mesh& b)
{
    SurfaceSpec sphere;
    sphere.correspondence = Correspondence::Sphere;
    sphere.correspondenceWhere = kWhere;
    return test::refusal(a, b, sphere);
}

TEST(SphereMerge, RefusesWhatIsNotAClosedGenusZeroSurface)
{
    const Mesh ball = test::radialSphere(
        7, 10, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "ball.obj");
    Mesh torus = test::torus(2.0, 0.5, 16, 8);
    torus.file = "torus.obj";
    const std::string genus = refusal(ball, torus);
    EXPECT_NE(genus.find("scene.toml:7:18: surface.correspondence = \"sphere\": torus.obj has "
                         "genus 1 (a sphere's is 0); the spherical map needs closed meshes of "
                         "genus 0 (sdf and variational modes morph any shapes)"),
              std::string::npos)
        << genus;
    Mesh open = ball;
    open.triangles.pop_back();
    analyzeTopology(open);
    EXPECT_NE(refusal(open, ball).find("ball.obj is not closed (3 boundary edges)"),
              std::string::npos);
}

TEST(SphereMerge, LandmarksThatWouldFoldTheMapAreRefusedAtTheirPair)
{
    const Mesh a = cShape(31, 12);
    Mesh b = cShape(23, 17);
    b.file = "b.obj";
    // Three points around the C's middle ring, then the same three the other way round.
    const auto ring = [](const Mesh& m, int rings, int around, int k) {
        return Vec3d(m.points[size_t((rings / 2) * around + k)]);
    };
    std::vector<SurfaceLandmark> mirrored;
    for (int k = 0; k < 3; ++k)
        mirrored.push_back(
            {ring(a, 31, 12, 4 * k), ring(b, 23, 17, (17 - 6 * k) % 17), {"s.toml", 5 + 4 * k, 1}});
    try {
        sphereMerge(a, b, mirrored, kWhere);
        ADD_FAILURE() << "mirrored landmarks were accepted";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("s.toml:5:1: [[pair]]: the landmarks (s.toml:5:1, "),
                  std::string::npos)
            << e.what();
        EXPECT_NE(
            std::string(e.what()).find("(mirrored): they cannot meet without folding the map"),
            std::string::npos)
            << e.what();
    }
}

} // namespace
} // namespace volmorph::detail
