// Kent's star-shaped merge (surface/StarMerge.h) and its parts: the exact orientation predicate
// with Simulation of Simplicity, the kernel's deepest point, and the overlay of two spherical
// triangulations, each against something independent: a determinant that double rounding gets
// wrong, the cube's centre, a brute-force count of arc crossings, the sphere's area 4 pi, and the
// merged meshes' volumes and areas against the inputs' (a refinement of a surface encloses the
// same volume).
#include "surface/SphereOverlay.h"
#include "surface/StarKernel.h"
#include "surface/StarMerge.h"

#include "support/MergeChecks.h"
#include "support/OpenMeshes.h"
#include "support/SurfaceChecks.h"
#include "support/SurfaceShapes.h"

#include <volmorph/SurfaceMorph.h>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

namespace volmorph::detail {
namespace {

double sphericalArea(const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    // Van Oosterom and Strackee 1983.
    return 2.0 * std::atan2(a.dot(b.cross(c)), 1.0 + a.dot(b) + b.dot(c) + c.dot(a));
}

/// A turn about an axis of no symmetry of the test meshes.
Vec3d turn(const Vec3d& v)
{
    const Eigen::Vector3d e = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.36, 0.48, 0.8)) *
                              Eigen::Vector3d(v.x(), v.y(), v.z());
    return {e.x(), e.y(), e.z()};
}

SphereTriangulation onSphere(const Mesh& m, const Vec3d& centre, bool turned)
{
    SphereTriangulation s;
    s.triangles = m.triangles;
    for (const Vec3f& p : m.points) {
        Vec3d d = Vec3d(p) - centre;
        d.normalize();
        s.directions.push_back(toGrid(turned ? turn(d) : d));
    }
    return s;
}

using test::area;
using test::checkMerge;
using test::distanceTo;
using test::pointsOf;
using test::refusal;
using test::volume;

TEST(SpherePredicates, ExactWhereDoubleRoundsAndTiesBrokenConsistently)
{
    // det = a d - b c = 2^80 - (2^80 - 1) = 1, which double rounds to 0.
    const int64_t t40 = int64_t(1) << 40;
    const GridDirection p{t40, t40 - 1, 0}, q{t40 + 1, t40, 0}, r{0, 0, 1};
    EXPECT_EQ(double(p.x) * double(q.y) - double(p.y) * double(q.x), 0.0);
    EXPECT_EQ(orientation(p, q, r), 1);
    EXPECT_EQ(orientation(q, p, r), -1);

    // Ties: coplanar with the centre, and a repeated direction. The simulated signs are never 0,
    // flip with a swap and keep under a cyclic turn.
    const GridDirection u{t40, 0, 0}, v{0, t40, 0}, w{t40, t40, 0};
    ASSERT_EQ(orientation(u, v, w), 0);
    for (const auto& [a, b, c] : {std::tuple{u, v, w}, std::tuple{u, u, v}, std::tuple{w, w, w}}) {
        const int s = orientationSoS(a, 0, b, 1, c, 2);
        EXPECT_NE(s, 0);
        EXPECT_EQ(orientationSoS(b, 1, a, 0, c, 2), -s);
        EXPECT_EQ(orientationSoS(b, 1, c, 2, a, 0), s);
        EXPECT_EQ(orientationSoS(a, 0, c, 2, b, 1), -s);
    }
}

TEST(StarKernel, TheCubesDeepestPointIsItsCentre)
{
    const Mesh c = test::cube(1.0, Vec3d(3.0, 4.0, 5.0));
    const KernelPoint k = deepestKernelPoint(pointsOf(c), c.triangles);
    EXPECT_NEAR((k.point - Vec3d(3.0, 4.0, 5.0)).length(), 0.0, 1e-9);
    EXPECT_NEAR(k.margin, 1.0, 1e-9);
    EXPECT_NEAR(kernelDepth(pointsOf(c), c.triangles, Vec3d(3.5, 4.0, 5.0)).margin, 0.5, 1e-12);
}

TEST(StarKernel, ATubeBentIntoACHasNone)
{
    const Mesh a = test::bent(test::tube(31, 12, 4.0, 0.3), 4.0, 1.7 * M_PI);
    EXPECT_LE(deepestKernelPoint(pointsOf(a), a.triangles).margin, 0.0);
}

/// Arcs p->q and r->s cross (double precision; the test meshes are far from ties).
bool arcsCross(const Vec3d& p, const Vec3d& q, const Vec3d& r, const Vec3d& s)
{
    const Vec3d x = p.cross(q).cross(r.cross(s));
    for (const Vec3d& c : {x, -x}) // on both arcs: between the ends along each great circle
        if (p.cross(c).dot(p.cross(q)) > 0.0 && c.cross(q).dot(p.cross(q)) > 0.0 &&
            r.cross(c).dot(r.cross(s)) > 0.0 && c.cross(s).dot(r.cross(s)) > 0.0)
            return true;
    return false;
}

TEST(SphereOverlay, TwoSpheresMergeIntoOneTriangulation)
{
    const Mesh ma = test::radialSphere(
        9, 14, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "a");
    const Mesh mb = test::radialSphere(
        13, 9, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "b");
    const SphereTriangulation a = onSphere(ma, Vec3d(0.0), false),
                              b = onSphere(mb, Vec3d(0.0), true);
    const Overlay o = overlay(a, b);
    const size_t na = a.directions.size(), nb = b.directions.size();
    ASSERT_EQ(o.vertices.size(), na + nb + o.crossings);
    for (size_t i = 0; i < na; ++i) EXPECT_EQ(o.grid[i], a.directions[i]);
    for (size_t j = 0; j < nb; ++j) EXPECT_EQ(o.grid[na + j], b.directions[j]);

    // Every crossing, counted by brute force over all pairs of edges.
    auto edges = [](const std::vector<Vec3I>& tris) {
        std::vector<std::pair<uint32_t, uint32_t>> e;
        for (const Vec3I& t : tris)
            for (int k = 0; k < 3; ++k)
                if (t[k] < t[(k + 1) % 3]) e.emplace_back(t[k], t[(k + 1) % 3]);
        return e;
    };
    size_t crossings = 0;
    for (const auto& [p, q] : edges(a.triangles))
        for (const auto& [r, s] : edges(b.triangles))
            crossings += arcsCross(fromGrid(a.directions[p]), fromGrid(a.directions[q]),
                                   fromGrid(b.directions[r]), fromGrid(b.directions[s]));
    EXPECT_EQ(o.crossings, crossings);

    // A closed, counter-clockwise triangulation covering the sphere once.
    EXPECT_EQ(invertedTriangles(o.grid, o.triangles), 0u);
    EXPECT_EQ(o.unclipped, 0u);
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    double total = 0.0;
    for (const Vec3I& t : o.triangles) {
        total += sphericalArea(o.directions[t[0]], o.directions[t[1]], o.directions[t[2]]);
        for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    }
    EXPECT_NEAR(total, 4.0 * M_PI, 1e-9);
    for (const auto& [e, n] : directed) {
        EXPECT_EQ(n, 1);
        EXPECT_EQ(directed.count({e.second, e.first}), 1u);
    }
    EXPECT_EQ(o.vertices.size() - o.triangles.size() / 2, 2u); // Euler: a sphere
}

const SourceLocation kWhere{"scene.toml", 7, 18};

TEST(StarMerge, ACubeIntoASphere)
{
    const Mesh a = test::cube(1.0, Vec3d(2.0, 0.0, 0.0));
    const Mesh b = test::radialSphere(
        16, 24, Vec3d(-1.0, 0.5, 0.0), [](const Vec3d&) { return 1.2; }, "sphere.obj");
    const Corresponded c = starMerge(a, b, std::nullopt, {}, kWhere);
    EXPECT_EQ(c.used, Correspondence::Star);
    checkMerge(a, b, c);
    std::printf("cube (8) into sphere (%zu): %zu merged vertices, %zu crossings\n", b.points.size(),
                c.source.size(), c.crossings);
}

TEST(StarMerge, TheSameMeshOnBothSidesDespiteEveryVertexCoinciding)
{
    const Mesh a = test::radialSphere(
        7, 10, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "a.obj");
    checkMerge(a, a, starMerge(a, a, std::nullopt, {}, kWhere));
}

TEST(StarMerge, ABlobIntoAnEllipsoidCarriesItsColours)
{
    auto blob = [](const Vec3d& d) {
        return 1.0 +
               0.3 * std::sin(3.0 * std::acos(d.z())) * std::cos(2.0 * std::atan2(d.y(), d.x()));
    };
    auto ellipsoid = [](const Vec3d& d) {
        return 1.0 / std::sqrt(d.x() * d.x() / 4.0 + d.y() * d.y() + d.z() * d.z() / 0.25);
    };
    Mesh a = test::radialSphere(20, 31, Vec3d(0.0, 0.0, 1.0), blob, "blob.obj");
    const Mesh b = test::radialSphere(11, 17, Vec3d(5.0, 0.0, 0.0), ellipsoid, "ellipsoid.obj");
    // A colour linear in position: barycentric interpolation reproduces it on each triangle.
    auto rgb = [](const Vec3d& p) {
        return Vec3d(0.5 + 0.2 * p.x(), 0.5 + 0.1 * p.y(), 0.4 + 0.1 * p.z());
    };
    for (const Vec3f& p : a.points) a.colors.emplace_back(rgb(Vec3d(p)));
    const Corresponded c =
        starMerge(a, b, std::pair{Vec3d(0.1, 0.0, 1.1), Vec3d(5.2, 0.1, 0.0)}, {}, kWhere);
    checkMerge(a, b, c);
    ASSERT_EQ(c.sourceColors.size(), c.source.size());
    for (size_t v = 0; v < c.source.size(); ++v) {
        const Vec3d expected = v < a.points.size() ? Vec3d(a.colors[v]) : rgb(c.source[v]);
        const Vec3d planar = Vec3d(c.sourceColors[v]);
        // The colour field's value where the vertex lies (to the colours' float rounding).
        EXPECT_LT((planar - expected).length(), 1e-6) << v;
        EXPECT_EQ(c.targetColors[v], Vec3f(0.8f)); // the target has none: grey
    }
}

TEST(StarMerge, RefusesWhatItCannotMergeNamingTheMeshAndWhatWasFound)
{
    SurfaceSpec star;
    star.correspondence = Correspondence::Star;
    star.correspondenceWhere = kWhere;
    const Mesh ball = test::radialSphere(
        7, 10, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "ball.obj");
    Mesh c = test::bent(test::tube(31, 12, 4.0, 0.3), 4.0, 1.7 * M_PI);
    c.file = "c.obj";
    const std::string notStar = refusal(c, ball, star);
    EXPECT_NE(notStar.find("scene.toml:7:18"), std::string::npos) << notStar;
    EXPECT_NE(notStar.find("c.obj is not star-shaped"), std::string::npos) << notStar;
    EXPECT_NE(notStar.find("cannot be seen"), std::string::npos) << notStar;
    EXPECT_NE(notStar.find("\"sphere\""), std::string::npos) << notStar;

    Mesh torus = test::torus(2.0, 0.5, 16, 8);
    torus.file = "torus.obj";
    EXPECT_NE(refusal(ball, torus, star).find("torus.obj has genus 1"), std::string::npos);

    Mesh open = ball;
    open.triangles.pop_back();
    analyzeTopology(open);
    EXPECT_NE(refusal(open, ball, star).find("ball.obj is not closed (3 boundary edges)"),
              std::string::npos);

    star.kernel = std::pair{Vec3d(1.5, 0.0, 0.0), Vec3d(0.0)};
    const std::string outside = refusal(ball, ball, star);
    EXPECT_NE(outside.find("surface.kernel: ball.obj is not seen whole from (1.5, 0, 0)"),
              std::string::npos)
        << outside;

    SurfaceSpec automatic; // auto: not the identity, not genus 0, not a disk
    automatic.where = kWhere;
    const std::string neither = refusal(torus, ball, automatic);
    EXPECT_NE(neither.find("surface.correspondence = \"auto\": the meshes differ in size"),
              std::string::npos)
        << neither;
    EXPECT_NE(neither.find("; and torus.obj has genus 1"), std::string::npos) << neither;
    EXPECT_NE(neither.find("torus.obj has no boundary"), std::string::npos) << neither;
    EXPECT_NE(neither.find("sdf and variational"), std::string::npos) << neither;
}

TEST(StarMerge, RigidInBetweensOfAMergeStartAndEndOnTheInputs)
{
    const Mesh a = test::cube(1.0, Vec3d(2.0, 0.0, 0.0));
    const Mesh b = test::radialSphere(
        10, 16, Vec3d(-1.0, 0.5, 0.0), [](const Vec3d&) { return 1.2; }, "sphere.obj");
    SurfaceSpec spec;
    spec.correspondence = Correspondence::Auto; // not the identity: the star merge
    const SurfaceMorpher m(a, b, spec);
    EXPECT_EQ(m.correspondence(), Correspondence::Star);
    const Corresponded c = starMerge(a, b, std::nullopt, {}, kWhere);
    test::expectEndsOnSides(m, c);
    // The velocity is the derivative of the positions.
    const double h = 1e-5;
    const SurfaceFrame mid = m.frame(0.4, 0.4), lo = m.frame(0.4 - h, 0.4),
                       hi = m.frame(0.4 + h, 0.4);
    double worst = 0.0, scale = 0.0;
    for (size_t v = 0; v < mid.points.size(); ++v) {
        const Vec3d fd = (hi.points[v] - lo.points[v]) / (2.0 * h);
        worst = std::max(worst, (fd - mid.velocity[v]).length());
        scale = std::max(scale, fd.length());
    }
    EXPECT_LT(worst, 0.01 * scale);
}

TEST(StarMerge, LandmarksMeet)
{
    const Mesh a = test::cube(1.0, Vec3d(2.0, 0.0, 0.0));
    const Mesh b = test::radialSphere(
        16, 24, Vec3d(-1.0, 0.5, 0.0), [](const Vec3d&) { return 1.2; }, "sphere.obj");
    // The top face onto the sphere's pole (a vertex), a point near a corner (off the cube, snapped)
    // onto its side, one more; none on a cube edge (there, the merge's tie-breaking turn would
    // leave the pair a millionth of the size apart).
    const std::vector<SurfaceLandmark> marks = {
        {Vec3d(2.3, 0.4, 1.0), Vec3d(-1.0, 0.5, 1.25), {"scene.toml", 10, 1}},
        {Vec3d(2.9, 0.9, 0.3), Vec3d(-1.0, 1.75, 0.0), {"scene.toml", 14, 1}},
        {Vec3d(1.0, -0.5, -0.2), Vec3d(-2.2, 0.5, -0.1), {"scene.toml", 18, 1}}};
    const Corresponded c = starMerge(a, b, std::nullopt, marks, kWhere);
    for (const SurfaceLandmark& l : marks)
        EXPECT_GE(test::meeting(c, a, b, l), 0) << l.where.str() << " does not meet";
    // Still a merge of the two surfaces: the target got a vertex per landmark not at one of its
    // own (the pole is), the surfaces are whole.
    ASSERT_EQ(c.source.size(), a.points.size() + b.points.size() + 2 + c.crossings);
    const std::vector<Vec3d> pa = pointsOf(a), pb = pointsOf(b);
    EXPECT_NEAR(volume(c.source, c.triangles) / volume(pa, a.triangles), 1.0, 1e-9);
    EXPECT_NEAR(volume(c.target, c.triangles) / volume(pb, b.triangles), 1.0, 1e-9);
}

TEST(StarMerge, LandmarksOffTheSurfaceOrFoldingTheMapAreRefusedAtTheirPair)
{
    const Mesh a = test::radialSphere(
        10, 16, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "a.obj");
    const Mesh b = test::radialSphere(
        12, 14, Vec3d(0.0), [](const Vec3d&) { return 1.0; }, "b.obj");
    try {
        starMerge(a, b, std::nullopt,
                  {{Vec3d(0.0, 0.0, 1.5), Vec3d(0.0, 0.0, 1.0), {"s.toml", 5, 1}}}, kWhere);
        ADD_FAILURE() << "a landmark half a radius off the surface was accepted";
    } catch (const UserError& e) {
        EXPECT_NE(
            std::string(e.what()).find("s.toml:5:1: [[pair]]: the source landmark (0, 0, 1.5) is"),
            std::string::npos)
            << e.what();
    }
    // Mirrored: three landmarks counter-clockwise on one side, clockwise on the other.
    const double r = 1.0 / std::sqrt(3.0);
    const std::vector<SurfaceLandmark> mirrored = {
        {Vec3d(1.0, 0.0, 0.0), Vec3d(1.0, 0.0, 0.0), {"s.toml", 5, 1}},
        {Vec3d(0.0, 1.0, 0.0), Vec3d(0.0, 0.0, 1.0), {"s.toml", 9, 1}},
        {Vec3d(0.0, 0.0, 1.0), Vec3d(0.0, 1.0, 0.0), {"s.toml", 13, 1}},
        {Vec3d(r, r, r), Vec3d(r, r, r), {"s.toml", 17, 1}}};
    try {
        starMerge(a, b, std::nullopt, mirrored, kWhere);
        ADD_FAILURE() << "mirrored landmarks were accepted";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("s.toml:5:1: [[pair]]: the landmarks (s.toml:5:1, "),
                  std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot meet without folding the map"),
                  std::string::npos);
    }
}

} // namespace
} // namespace volmorph::detail
