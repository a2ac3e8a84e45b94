#include <volmorph/Export.h>
#include <volmorph/Feature.h>
#include <volmorph/Morph.h>
#include <volmorph/Voxelize.h>
#include <volmorph/Warp.h>

#include "morph/Stretch.h"      // private to the library; tested directly
#include "warp/AdaptiveWarp.h" // private to the library; tested directly

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/Morphology.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <tuple>

using namespace volmorph;

namespace {

const std::filesystem::path kMeshes = std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";

FeatureElement element(const Vec3d& origin, const Vec3d& x = Vec3d(1, 0, 0), const Vec3d& y = Vec3d(0, 1, 0),
                       const Vec3d& scale = Vec3d(1.0))
{
    FeatureElement e;
    e.origin = origin;
    e.xAxis = x.unit();
    e.yAxis = y.unit();
    e.zAxis = e.xAxis.cross(e.yAxis);
    e.scale = scale;
    return e;
}

FeaturePairSpec pair(FeatureType type, const FeatureElement& s, const FeatureElement& t)
{
    FeaturePairSpec p;
    p.type = type;
    p.source = s;
    p.target = t;
    return p;
}

VolumeSet voxelized(const std::string& mesh, double voxelSize, const ObjectTransform& xf = {})
{
    VoxelizeOptions o;
    o.voxelSize = voxelSize;
    return voxelize(importMesh(kMeshes / mesh, xf), o);
}

struct Moments {
    double mass = 0.0;
    Vec3d centroid{0.0};
    double ixx = 0, iyy = 0, ixy = 0; ///< central second moments in the xy plane
};

Moments moments(const openvdb::FloatGrid& density)
{
    Moments m;
    std::vector<std::pair<Vec3d, double>> samples;
    for (auto it = density.cbeginValueOn(); it; ++it) {
        const openvdb::CoordBBox b = it.getBoundingBox();
        if (it.isVoxelValue()) {
            samples.emplace_back(density.indexToWorld(it.getCoord()), double(*it));
        } else {
            for (auto c = b.begin(); c; ++c) samples.emplace_back(density.indexToWorld(*c), double(*it));
        }
    }
    for (const auto& [p, w] : samples) {
        m.mass += w;
        m.centroid += w * p;
    }
    m.centroid /= m.mass;
    for (const auto& [p, w] : samples) {
        const Vec3d d = p - m.centroid;
        m.ixx += w * d.x() * d.x();
        m.iyy += w * d.y() * d.y();
        m.ixy += w * d.x() * d.y();
    }
    return m;
}

/// Largest |a - b| of two density grids over the union of their active voxels.
double maxDifference(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
{
    double worst = 0.0;
    auto ba = b.getConstAccessor();
    for (auto it = a.cbeginValueOn(); it; ++it)
        for (auto c = it.getBoundingBox().begin(); c; ++c)
            worst = std::max(worst, double(std::abs(a.tree().getValue(*c) - ba.getValue(*c))));
    auto aa = a.getConstAccessor();
    for (auto it = b.cbeginValueOn(); it; ++it)
        for (auto c = it.getBoundingBox().begin(); c; ++c)
            worst = std::max(worst, double(std::abs(aa.getValue(*c) - b.tree().getValue(*c))));
    return worst;
}

/// Rodrigues' rotation of v about the unit axis k by angle (radians).
Vec3d rotate(const Vec3d& v, const Vec3d& k, double angle)
{
    return v * std::cos(angle) + k.cross(v) * std::sin(angle) + k * (k.dot(v) * (1.0 - std::cos(angle)));
}

/// A random configuration of n pairs of random types inside a cube of `extent` units, made the way
/// a user makes them: each target element is its source element moved by up to a quarter of the
/// extent, scaled by 0.6 to 1.6 per axis and turned by up to 60 degrees.
std::vector<FeaturePairSpec> randomPairs(std::mt19937& random, int n, double extent)
{
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto vec = [&] { return Vec3d(u(random), u(random), u(random)); };
    auto direction = [&] {
        Vec3d d = vec() - Vec3d(0.5);
        while (d.length() < 0.1) d = vec() - Vec3d(0.5);
        return d.unit();
    };
    std::vector<FeaturePairSpec> pairs;
    for (int i = 0; i < n; ++i) {
        FeaturePairSpec p;
        p.type = FeatureType(random() % 4);
        FeatureElement& s = p.source;
        s.origin = vec() * extent;
        s.xAxis = direction();
        Vec3d across = s.xAxis.cross(direction());
        while (across.length() < 0.1) across = s.xAxis.cross(direction()); // a frame, not a near-degenerate one
        s.yAxis = across.unit();
        s.zAxis = s.xAxis.cross(s.yAxis);
        s.scale = (Vec3d(0.1) + vec()) * (extent / 4);
        FeatureElement& t = p.target;
        t.origin = s.origin + (vec() - Vec3d(0.5)) * (extent / 2);
        const Vec3d axis = direction();
        const double angle = (u(random) - 0.5) * (2.0 * M_PI / 3.0);
        t.xAxis = rotate(s.xAxis, axis, angle);
        t.yAxis = rotate(s.yAxis, axis, angle);
        t.zAxis = t.xAxis.cross(t.yAxis);
        const Vec3d factor = Vec3d(0.6) + vec();
        t.scale = Vec3d(s.scale.x() * factor.x(), s.scale.y() * factor.y(), s.scale.z() * factor.z());
        pairs.push_back(p);
    }
    return pairs;
}

/// The largest distance between a leaf's approximated points and the exact warp's, on either side,
/// over every `stride`-th voxel.
double leafError(const InverseWarp& warp, const detail::WarpLeaf& leaf, int stride)
{
    double local = 0.0;
    Vec3d s, d;
    for (int i = 0; i < 512; i += stride) {
        warp.map(leaf.origin.offsetBy(i >> 6, (i >> 3) & 7, i & 7).asVec3d(), s, d);
        local = std::max({local, (Vec3d(leaf.source(i)) - s).length(), (Vec3d(leaf.target(i)) - d).length()});
    }
    return local;
}

/// The largest leafError over every leaf of the box [0, last]^3 (index space).
double largestError(const InverseWarp& warp, const detail::AdaptiveWarp& adaptive, int last, int stride,
                    detail::AdaptiveWarpStats& stats)
{
    std::mutex m;
    double worst = 0.0;
    adaptive.forEachLeaf(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(last)), nullptr, nullptr,
                         [&](const detail::WarpLeaf& leaf) {
                             const double local = leafError(warp, leaf, stride);
                             std::lock_guard<std::mutex> lock(m);
                             worst = std::max(worst, local);
                         },
                         &stats);
    return worst;
}

} // namespace

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
    Feature f = Feature::fromElement(element(Vec3d(1, 2, 3), Vec3d(0, 0, 1), Vec3d(0, 1, 0), Vec3d(2, 3, 4)),
                                     FeatureType::Box);
    const Vec3d p(0.3, -1.2, 7.0);
    EXPECT_NEAR((f.fromLocal(f.toLocal(p)) - p).length(), 0.0, 1e-12);
    EXPECT_NEAR((f.toLocal(Vec3d(1, 2, 5)) - Vec3d(1.0, 0.0, 0.0)).length(), 0.0, 1e-12); // 2 along x = +z
}

TEST(Feature, SlerpTakesTheShorterArc)
{
    const Feature a = Feature::fromElement(element(Vec3d(0.0)), FeatureType::Box);
    // b is rotated 90 degrees about z: x -> y.
    const Feature b = Feature::fromElement(element(Vec3d(2, 0, 0), Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(3.0)),
                                           FeatureType::Box);
    const Feature m = interpolate(a, b, 0.5);
    EXPECT_NEAR((m.x - Vec3d(std::sqrt(0.5), std::sqrt(0.5), 0)).length(), 0.0, 1e-9);
    EXPECT_NEAR((m.z - Vec3d(0, 0, 1)).length(), 0.0, 1e-9);
    EXPECT_NEAR((m.origin - Vec3d(1, 0, 0)).length(), 0.0, 1e-12);
    EXPECT_NEAR((m.scale - Vec3d(2.0)).length(), 0.0, 1e-12);
    // 270 degrees one way is 90 the other: the interpolant turns by -45 degrees, not +135.
    const Feature c = Feature::fromElement(element(Vec3d(0.0), Vec3d(0, -1, 0), Vec3d(1, 0, 0)), FeatureType::Box);
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
        const double angle = i % 4 == 0 ? M_PI * (1.0 - 1e-3 * std::abs(u(random))) : M_PI * u(random);
        const Vec3d x = rotate(Vec3d(1, 0, 0), axis, angle), y = rotate(Vec3d(0, 1, 0), axis, angle);
        const Vec3d z = x.cross(y);
        const openvdb::math::Quatd q = rotationQuaternion(x, y, z);
        EXPECT_NEAR(std::sqrt(q.dot(q)), 1.0, 1e-14);
        // The quaternion gives the frame back, in the convention rotation<Mat3> reads it.
        const auto m = openvdb::math::rotation<openvdb::math::Mat3d>(q);
        EXPECT_NEAR((m.row(0) - x).length() + (m.row(1) - y).length() + (m.row(2) - z).length(), 0.0, 1e-12);
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
    EXPECT_THROW(openvdb::math::Quatd(openvdb::math::Mat3d(b.x, b.y, b.z, true)), openvdb::ArithmeticError);
    const Feature m = interpolate(a, b, 0.5);
    EXPECT_NEAR((m.x - Vec3d(1, 0, 0)).length(), 0.0, 1e-12);
}

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
    w.map(Vec3d(5, 2, 0), s, t); // at t = 1 the output is target space: the target side is the identity
    EXPECT_NEAR((t - Vec3d(5, 2, 0)).length(), 0.0, 1e-12);
    EXPECT_NEAR((s - Vec3d(1, 0, 0)).length(), 0.0, 1e-12); // 2 along target x (= +y) is 1 along source x
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
    // t = 1, so move off-centre: weights 1/d^2 are equal; use t = 0.5 with elements at -0.5 and 0.5.
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
        for (const Vec3d& p : {Vec3d(0.0), Vec3d(0.2, 0, 0), Vec3d(2, 2, 2 + t), Vec3d(1e6, -1e6, 3)}) {
            Vec3d s, d;
            w.map(p, s, d);
            for (int k = 0; k < 3; ++k) {
                EXPECT_TRUE(std::isfinite(s[k]) && std::isfinite(d[k])) << p << " at t " << t;
            }
        }
    }
}

TEST(Stretch, SpectralNormMatchesOpenVdbsDiagonalization)
{
    // The closed form against OpenVDB's Jacobi iteration, on random Jacobians and on the
    // degenerate ones (repeated eigenvalues, rank 1 and 0, diagonal).
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    std::vector<std::array<Vec3d, 3>> cases = {
        {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)},       {Vec3d(2, 0, 0), Vec3d(0, 3, 0), Vec3d(0, 0, 0.5)},
        {Vec3d(1, 2, 3), Vec3d(2, 4, 6), Vec3d(-1, -2, -3)},     {Vec3d(0.0), Vec3d(0.0), Vec3d(0.0)},
        {Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(0, 0, 1)},       {Vec3d(1, 1e-9, 0), Vec3d(0, 1, 1e-9), Vec3d(1e-9, 0, 1)},
    };
    for (int i = 0; i < 1000; ++i) cases.push_back({Vec3d(u(random), u(random), u(random)), Vec3d(u(random), u(random), u(random)), Vec3d(u(random), u(random), u(random))});
    for (const auto& [dx, dy, dz] : cases) {
        const openvdb::math::Mat3d j(dx.x(), dy.x(), dz.x(), dx.y(), dy.y(), dz.y(), dx.z(), dy.z(), dz.z());
        openvdb::math::Mat3d q;
        Vec3d eigen;
        ASSERT_TRUE(openvdb::math::diagonalizeSymmetricMatrix(j.transpose() * j, q, eigen));
        const double expected = std::sqrt(std::max({eigen.x(), eigen.y(), eigen.z(), 0.0}));
        EXPECT_NEAR(detail::spectralNorm(dx, dy, dz), expected, 1e-7 * std::max(1.0, expected)) << dx << dy << dz;
    }
}

TEST(AdaptiveWarp, WithinToleranceOfTheExactWarpOnRandomConfigurations)
{
    // Inverse-square weights at t = 1/4 and 3/4, Beier-Neely's at t = 1/2. The bound behind the
    // approximation is a worst case, so the error is checked at every voxel, not sampled.
    std::mt19937 random(2024);
    for (int n : {1, 2, 4, 8, 16, 32, 64}) {
        for (int trial = 0; trial < 3; ++trial) {
            const auto pairs = randomPairs(random, n, 96.0);
            WarpSpec spec;
            spec.epsilon = 2.0; // index units here (unit = 1)
            if (trial == 2) {
                spec.weighting = Weighting::BeierNeely;
                spec.a = 2.0;
                spec.b = 2.0;
                spec.p = 0.5;
            }
            const double t = 0.25 + 0.25 * trial;
            const InverseWarp warp(pairs, spec, t);
            const double tolerance = 0.25;
            const detail::AdaptiveWarp adaptive(warp, tolerance);
            detail::AdaptiveWarpStats stats;
            // Every voxel up to 16 pairs; every 3rd beyond keeps the test quick.
            const double worst = largestError(warp, adaptive, 95, n <= 16 ? 1 : 3, stats);
            EXPECT_LE(worst, tolerance) << n << " pairs, trial " << trial;
            EXPECT_LE(stats.maxErrorVoxels, tolerance);
            EXPECT_EQ(stats.leaves, 12u * 12u * 12u);
            // Pairs packed this densely (2 voxels of epsilon, elements 2-26 voxels, moved up to
            // 24) leave most pairs near most voxels; the next test is the efficient case.
            const double pairEvaluations = double(stats.exactEvaluations) * n + double(stats.nearEvaluations);
            EXPECT_LE(pairEvaluations, 1.01 * 96.0 * 96 * 96 * n);
        }
    }
}

TEST(AdaptiveWarp, ErrorBoundHoldsAtEveryVoxelOfEveryLeaf)
{
    // Each leaf's a-priori bound against the exact warp at its voxels, from tolerances that make
    // most pairs near down to none but the kinks (a huge tolerance), for both weight laws: the
    // bound must hold leaf by leaf, not only below the tolerance. Single-precision points allow
    // 1e-3 voxel of rounding beyond it.
    std::mt19937 random(1999);
    double tightest = 0.0; // the largest error / bound seen (how tight the bound is)
    size_t checked = 0;
    for (int n : {1, 2, 4, 8, 16, 32, 64}) {
        for (int trial = 0; trial < 2; ++trial) {
            const auto pairs = randomPairs(random, n, 64.0);
            WarpSpec spec;
            spec.epsilon = trial == 0 ? 1.0 : 4.0;
            if (trial == 1) {
                spec.weighting = Weighting::BeierNeely;
                spec.a = 3.0;
                spec.b = 1.5;
                spec.p = 0.5;
            }
            const InverseWarp warp(pairs, spec, 0.4 + 0.2 * trial);
            for (double tolerance : {0.05, 0.5, 4.0, 1e6}) {
                const detail::AdaptiveWarp adaptive(warp, tolerance);
                std::mutex m;
                adaptive.forEachLeaf(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(63)), nullptr, nullptr,
                                     [&](const detail::WarpLeaf& leaf) {
                                         const double local = leafError(warp, leaf, n <= 16 ? 1 : 3);
                                         std::lock_guard<std::mutex> lock(m);
                                         ++checked;
                                         EXPECT_LE(local, leaf.errorBound + 1e-3)
                                             << n << " pairs, trial " << trial << ", tolerance " << tolerance
                                             << ", leaf " << leaf.origin;
                                         if (leaf.errorBound > 1e-3) tightest = std::max(tightest, local / leaf.errorBound);
                                     });
            }
        }
    }
    EXPECT_EQ(checked, 7u * 2u * 4u * 512u);
    std::printf("largest error / bound over the leaves: %.3f\n", tightest);
}

TEST(AdaptiveWarp, VectorAndBaselineKernelsGiveTheSameBits)
{
    // The leaf kernel, the bound and the lattice's sums run in AVX2 (or AVX2 with AVX-512VL) where
    // the CPU has it, each build compared with the baseline here; a farm
    // mixing machines must still get the same frames. Every pair type, near and far pairs, both
    // weight laws, with and without the domain test (trial 2: occupancies of a sphere on both
    // sides, so that cells, leaves and the filled points' boxes are culled), compared bit for bit.
    std::mt19937 random(7);
    const auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(30.0f, openvdb::Vec3f(40.0f, 50.0f, 45.0f), 1.0f);
    const detail::Occupancy occupancy(sphere->tree());
    for (int trial = 0; trial < 3; ++trial) {
        const auto pairs = randomPairs(random, 12, 96.0);
        WarpSpec spec;
        spec.epsilon = 2.0;
        if (trial == 1) {
            spec.weighting = Weighting::BeierNeely;
            spec.a = 2.0;
            spec.b = 2.0;
            spec.p = 0.5;
        }
        const InverseWarp warp(pairs, spec, 0.4);
        // 0.25: most leaves have near pairs; 1e6: only the kinks are near, and the other leaves
        // take the kernel's path with no near pair.
        for (const double tolerance : {0.25, 1e6}) {
            const detail::AdaptiveWarp adaptive(warp, tolerance);
            auto run = [&](detail::KernelBuild build) {
                detail::useKernelBuild(build);
                std::mutex m;
                std::map<std::tuple<int, int, int>, std::vector<float>> leaves;
                detail::AdaptiveWarpStats stats;
                const detail::Occupancy* occ = trial == 2 ? &occupancy : nullptr;
                adaptive.forEachLeaf(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(95)), occ, occ,
                                     [&](const detail::WarpLeaf& leaf) {
                                         std::vector<float> v(&leaf.s[0][0], &leaf.s[0][0] + 3 * 512);
                                         v.insert(v.end(), &leaf.t[0][0], &leaf.t[0][0] + 3 * 512);
                                         std::lock_guard<std::mutex> lock(m);
                                         leaves[{leaf.origin.x(), leaf.origin.y(), leaf.origin.z()}] = std::move(v);
                                     },
                                     &stats);
                detail::useKernelBuild(detail::KernelBuild::Avx512);
                EXPECT_GT(stats.nearEvaluations, 0u); // the near-pair loops ran
                if (tolerance > 1.0) {
                    EXPECT_GT(stats.allFarLeaves, 0u); // and the path without them
                }
                return leaves;
            };
            const auto baseline = run(detail::KernelBuild::Baseline);
            if (trial < 2) {
                ASSERT_EQ(baseline.size(), 12u * 12u * 12u);
            } else {
                ASSERT_GT(baseline.size(), 0u);
                ASSERT_LT(baseline.size(), 12u * 12u * 12u); // the domain test culled leaves
            }
            // Each vector build this CPU has (the baseline alone where it has none).
            for (const detail::KernelBuild build : {detail::KernelBuild::Avx2, detail::KernelBuild::Avx512}) {
                detail::useKernelBuild(build);
                const bool available = detail::activeKernelBuild() == build;
                detail::useKernelBuild(detail::KernelBuild::Avx512);
                if (!available) continue;
                const auto vector = run(build);
                ASSERT_EQ(vector.size(), baseline.size());
                size_t differing = 0;
                for (const auto& [origin, v] : vector)
                    differing += std::memcmp(v.data(), baseline.at(origin).data(), v.size() * sizeof(float)) != 0;
                EXPECT_EQ(differing, 0u) << "build " << int(build) << ", trial " << trial << ", tolerance " << tolerance;
            }
        }
    }
}

TEST(AdaptiveWarp, FewPairEvaluationsWherePairsAreApart)
{
    // Eight pairs of each type at the corners of a 2^3 grid 96 voxels apart, moved by up to 8
    // voxels and turned by up to 20 degrees, epsilon 4 voxels: most of the 192^3 box is far
    // from all of them, and most of the exact warp's pair evaluations are saved (0.22 of them are
    // made; the bound is a worst case, some 10 times the error actually made).
    std::mt19937 random(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<FeaturePairSpec> pairs;
    for (int k = 0; k < 8; ++k) {
        const Vec3d at(48.0 + 96 * (k & 1), 48.0 + 96 * ((k >> 1) & 1), 48.0 + 96 * ((k >> 2) & 1));
        const Vec3d axis = Vec3d(u(random), u(random), u(random) + 2.0).unit();
        const double angle = u(random) * M_PI / 9.0;
        pairs.push_back(pair(FeatureType(k % 4), element(at, Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(12, 8, 6)),
                             element(at + 8.0 * Vec3d(u(random), u(random), u(random)), rotate(Vec3d(1, 0, 0), axis, angle),
                                     rotate(Vec3d(0, 1, 0), axis, angle), Vec3d(14, 7, 6))));
    }
    WarpSpec spec;
    spec.epsilon = 4.0;
    const InverseWarp warp(pairs, spec, 0.5);
    const detail::AdaptiveWarp adaptive(warp, 0.25);
    detail::AdaptiveWarpStats stats;
    const double worst = largestError(warp, adaptive, 191, 1, stats);
    const double voxels = 192.0 * 192 * 192;
    const double share = (double(stats.exactEvaluations) * 8 + double(stats.nearEvaluations)) / (8 * voxels);
    std::cout << "largest error " << worst << " voxel, bound " << stats.maxErrorVoxels << ", pair evaluations "
              << share << " of the exact warp's\n";
    EXPECT_LE(worst, 0.25);
    EXPECT_LE(stats.maxErrorVoxels, 0.25);
    EXPECT_LT(share, 0.3);
}

TEST(AdaptiveWarp, OccupancyBoxQueriesMatchTheTree)
{
    // Occupancy answers box queries from a summed-volume table; the tree, scanned block by block,
    // is the reference.
    openvdb::FloatTree tree(0.0f);
    std::mt19937 random(7);
    std::uniform_int_distribution<int> coord(-200, 200);
    for (int i = 0; i < 3000; ++i) tree.setValue(openvdb::Coord(coord(random), coord(random), coord(random)), 1.0f);
    tree.fill(openvdb::CoordBBox(openvdb::Coord(256), openvdb::Coord(256 + 127)), 1.0f, true); // a tile
    const detail::Occupancy occupancy(tree);
    openvdb::MaskTree blocks; // the same rule: blocks with active values
    auto block = [](int v) { return v >= 0 ? v / 8 : -((-v + 7) / 8); };
    for (auto it = tree.cbeginValueOn(); it; ++it)
        for (auto c = it.getBoundingBox().begin(); c; ++c)
            blocks.setValueOn(openvdb::Coord(block((*c).x()), block((*c).y()), block((*c).z())));
    std::uniform_int_distribution<int> size(0, 40);
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
        const openvdb::Coord lo(coord(random) * 2, coord(random) * 2, coord(random) * 2);
        const openvdb::CoordBBox box(lo, lo.offsetBy(size(random), size(random), size(random)));
        bool expected = false;
        for (int x = block(box.min().x()); x <= block(box.max().x()) && !expected; ++x)
            for (int y = block(box.min().y()); y <= block(box.max().y()) && !expected; ++y)
                for (int z = block(box.min().z()); z <= block(box.max().z()) && !expected; ++z)
                    expected = blocks.isValueOn(openvdb::Coord(x, y, z));
        ASSERT_EQ(occupancy.anyIn(box), expected) << box;
        hits += expected;
    }
    EXPECT_GT(hits, 100); // both answers were exercised
    EXPECT_LT(hits, 2900);
}

TEST(Morph, PointPairTranslatesTheSphereLinearly)
{
    const double voxel = 0.04;
    ObjectTransform moved;
    moved.translate = Vec3d(1, 0, 0);
    const VolumeSet s = voxelized("sphere.obj", voxel), d = voxelized("sphere.obj", voxel, moved);
    const Morpher morpher(s, d, {pair(FeatureType::Point, element(Vec3d(0.0)), element(Vec3d(1, 0, 0)))}, WarpSpec{},
                          BlendSpec{});
    const double c0 = moments(*s.density).centroid.x();
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        const Moments m = moments(*morpher.frame(t).density);
        EXPECT_NEAR(m.centroid.x() - c0, t, 0.1 * voxel) << "t " << t;
        EXPECT_NEAR(m.centroid.y(), 0.0, 1e-3);
    }
}

TEST(Morph, BoxPairRotatesThePrincipalAxis)
{
    // A bar along x becomes the same bar along y; halfway, it lies at 45 degrees.
    const double voxel = 0.02;
    ObjectTransform bar, turned;
    bar.scale = Vec3d(1.0, 0.3, 0.3);
    turned.scale = Vec3d(1.0, 0.3, 0.3);
    turned.rotateRadians = Vec3d(0, 0, M_PI / 2);
    const VolumeSet s = voxelized("cube.obj", voxel, bar), d = voxelized("cube.obj", voxel, turned);
    const auto p = pair(FeatureType::Box, element(Vec3d(0.0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(1, 0.3, 0.3)),
                        element(Vec3d(0.0), Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(1, 0.3, 0.3)));
    const Morpher morpher(s, d, {p}, WarpSpec{}, BlendSpec{});
    const Moments m = moments(*morpher.frame(0.5).density);
    const double angle = 0.5 * std::atan2(2.0 * m.ixy, m.ixx - m.iyy);
    EXPECT_NEAR(angle * 180.0 / M_PI, 45.0, 0.5);
    EXPECT_NEAR(m.mass * std::pow(voxel, 3), 0.09, 0.09 * 0.02); // the bar's volume (1 x 0.3 x 0.3) is kept
}

TEST(Morph, ScalingPairScalesTheVolumeCubically)
{
    // Both sides warped to the same sphere scaled by 1 + t, in either blend mode.
    const double voxel = 0.02;
    ObjectTransform twice;
    twice.scale = Vec3d(2.0);
    const VolumeSet s = voxelized("sphere.obj", voxel), d = voxelized("sphere.obj", voxel, twice);
    const auto p = pair(FeatureType::Box, element(Vec3d(0.0)), element(Vec3d(0.0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(2.0)));
    const double v0 = moments(*s.density).mass;
    for (BlendMode mode : {BlendMode::Density, BlendMode::Sdf}) {
        BlendSpec blend;
        blend.mode = mode;
        const Morpher morpher(s, d, {p}, WarpSpec{}, blend);
        for (double t : {0.25, 0.5, 0.75}) {
            const double scale = 1.0 + t;
            EXPECT_NEAR(moments(*morpher.frame(t).density).mass / v0, scale * scale * scale, 0.02 * scale * scale * scale)
                << "t " << t << (mode == BlendMode::Sdf ? " (sdf)" : " (density)");
        }
    }
}

TEST(Morph, IdenticalSidesGiveTheSourceAtEveryFrame)
{
    const VolumeSet s = voxelized("bunny.obj", 0.3); // the scan is 10 units tall: ~33 voxels
    std::mt19937 random(5);
    auto pairs = randomPairs(random, 6, 10.0);
    for (auto& p : pairs) p.target = p.source;
    const Morpher morpher(s, s, pairs, WarpSpec{}, BlendSpec{});
    for (double t : {0.0, 0.3, 0.7, 1.0}) EXPECT_LT(maxDifference(*morpher.frame(t).density, *s.density), 1e-5) << t;
}

TEST(Morph, EndsAreSourceAndTarget)
{
    ObjectTransform xf;
    xf.scale = Vec3d(0.1);
    const double voxel = 0.02;
    const VolumeSet s = voxelized("bunny.obj", voxel, xf);
    ObjectTransform up;
    up.translate = Vec3d(0, 0.5, 0);
    const VolumeSet d = voxelized("knot1.off", voxel, up);
    const Scene scene = loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
    BlendSpec blend = scene.blend;
    blend.mode = BlendMode::Density; // the density path; SdfModeReproducesTheEndSurfaces covers sdf
    const Morpher morpher(s, d, scene.pairs, scene.warp, blend);
    EXPECT_LT(maxDifference(*morpher.frame(0.0).density, *s.density), 1e-4);
    EXPECT_LT(maxDifference(*morpher.frame(1.0).density, *d.density), 1e-4);
}

namespace {

/// The unit cube scaled by 0.7 and moved by `translate` (world units), voxelized.
VolumeSet smallCubeAt(const Vec3d& translate, double voxel)
{
    ObjectTransform xf;
    xf.translate = translate;
    xf.scale = Vec3d(0.7);
    return voxelized("cube.obj", voxel, xf);
}

} // namespace

// The sparse domain against evaluation at every voxel of a box well past the candidate box, in both
// blend modes. In sdf mode the blend is evaluated only in the leaves (and quarters of leaves) that
// can hold its band, judged from their centres with the warp's stretch; the rest is inside or
// outside as a whole. Both must give the same grids, exactly.
TEST(Morph, SparseDomainLosesNothing)
{
    const double voxel = 0.05;
    const VolumeSet s = voxelized("sphere.obj", voxel), d = smallCubeAt(Vec3d(0.8, 0.2, 0), voxel);
    std::mt19937 random(11);
    for (BlendMode mode : {BlendMode::Density, BlendMode::Sdf}) {
        BlendSpec blend;
        blend.mode = mode;
        for (int trial = 0; trial < 6; ++trial) {
            auto pairs = randomPairs(random, 1 + trial * 3, 1.0);
            for (auto& p : pairs) { // world units here: origins and scales inside the objects' region
                for (FeatureElement* e : {&p.source, &p.target}) e->origin -= Vec3d(0.3);
            }
            WarpSpec spec;
            spec.epsilon = 0.05;
            const Morpher morpher(s, d, pairs, spec, blend);
            const double t = (trial % 3 + 1) * 0.25;
            MorphStats sparseStats, denseStats;
            const VolumeSet sparse = morpher.frame(t, &sparseStats);
            openvdb::CoordBBox big = morpher.candidateBounds(t);
            big.expand(big.dim().x() / 4); // well past the candidate box
            const VolumeSet dense = morpher.frameOverBox(t, big, spec.toleranceVoxels, &denseStats);
            const std::string where = std::string(mode == BlendMode::Sdf ? "sdf" : "density") + " trial " +
                                      std::to_string(trial);
            ASSERT_GT(sparse.density->activeVoxelCount(), 0u) << where;
            EXPECT_EQ(maxDifference(*sparse.density, *dense.density), 0.0) << where;
            EXPECT_EQ(sparse.color->activeVoxelCount(), dense.color->activeVoxelCount()) << where;
            if (mode == BlendMode::Sdf) {
                EXPECT_EQ(maxDifference(*sparse.sdf, *dense.sdf), 0.0) << where;
                EXPECT_LT(sparseStats.blendSamples, denseStats.blendSamples / 10) << where;
            } else {
                EXPECT_LT(sparseStats.candidateLeaves, denseStats.candidateLeaves) << where;
            }
        }
    }
}

// With no pairs, sdf-mode frames read the distances kept across frames (Morpher's
// IdentityDistances) instead of sampling through the warp. They must equal the dense reference,
// which samples every voxel, exactly, also when a frame is made again from what is kept.
TEST(Morph, SdfFramesWithoutPairsMatchTheDenseReference)
{
    const double voxel = 0.05;
    const VolumeSet s = voxelized("sphere.obj", voxel), d = smallCubeAt(Vec3d(0.5, 0.2, 0), voxel);
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const Morpher morpher(s, d, {}, WarpSpec{}, blend);
    uint64_t firstSamples = 0;
    for (double t : {0.5, 0.2, 0.8, 0.5}) {
        MorphStats sparseStats;
        const VolumeSet sparse = morpher.frame(t, &sparseStats);
        openvdb::CoordBBox big = morpher.candidateBounds(t);
        big.expand(big.dim().x() / 4);
        const VolumeSet dense = morpher.frameOverBox(t, big, 0.0);
        const std::string where = "t = " + std::to_string(t);
        ASSERT_GT(sparse.density->activeVoxelCount(), 0u) << where;
        EXPECT_EQ(maxDifference(*sparse.sdf, *dense.sdf), 0.0) << where;
        EXPECT_EQ(maxDifference(*sparse.density, *dense.density), 0.0) << where;
        EXPECT_EQ(sparse.color->activeVoxelCount(), dense.color->activeVoxelCount()) << where;
        auto denseColor = dense.color->getConstAccessor();
        double worstColor = 0.0;
        for (auto it = sparse.color->cbeginValueOn(); it; ++it)
            worstColor = std::max(worstColor, double((*it - denseColor.getValue(it.getCoord())).length()));
        EXPECT_EQ(worstColor, 0.0) << where;
        if (firstSamples == 0) firstSamples = sparseStats.blendSamples;
    }
    // The last frame repeats the first: every distance it needs is kept, none is sampled again.
    MorphStats again;
    morpher.frame(0.5, &again);
    EXPECT_LT(again.blendSamples, firstSamples / 4);
}

namespace {

/// The largest displacement between the zero sets of two level sets, in voxels, measured on the
/// grid near either surface (|a| or |b| < half a voxel). With unit gradients the displacement of
/// the zero set there is |a - b| (|b| alone would add up to the half voxel of the sample's offset).
double surfaceDistanceVoxels(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
{
    const double voxel = a.voxelSize()[0];
    double worst = 0.0;
    auto one = [&](const openvdb::FloatGrid& x, const openvdb::FloatGrid& y) {
        auto ya = y.getConstAccessor();
        for (auto it = x.cbeginValueOn(); it; ++it)
            if (std::abs(*it) < 0.5 * voxel)
                worst = std::max(worst, std::abs(double(ya.getValue(it.getCoord())) - double(*it)) / voxel);
    };
    one(a, b);
    one(b, a);
    return worst;
}

} // namespace

TEST(Morph, SdfModeReproducesTheEndSurfaces)
{
    const Scene scene = loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
    ASSERT_EQ(scene.blend.mode, BlendMode::Sdf);
    ObjectTransform xf;
    xf.scale = Vec3d(0.1);
    ObjectTransform up;
    up.translate = Vec3d(0, 0.5, 0);
    const double voxel = 0.016;
    const VolumeSet s = voxelized("bunny.obj", voxel, xf), d = voxelized("knot1.off", voxel, up);
    const Morpher morpher(s, d, scene.pairs, scene.warp, scene.blend);
    const VolumeSet first = morpher.frame(0.0), last = morpher.frame(1.0);
    ASSERT_TRUE(first.sdf && last.sdf);
    EXPECT_EQ(first.sdf->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_LE(surfaceDistanceVoxels(*first.sdf, *s.sdf), 1.0);
    EXPECT_LE(surfaceDistanceVoxels(*last.sdf, *d.sdf), 1.0);
    // In between there is one surface: the fog comes from the blended level set alone.
    const VolumeSet mid = morpher.frame(0.5);
    EXPECT_LT(maxDifference(*mid.density, *fogFromLevelSet(*mid.sdf, 1.5f * float(voxel))), 1e-6);
}

TEST(Morph, InBetweenExportsAsAClosedColouredMesh)
{
    const double voxel = 0.02;
    ObjectTransform moved;
    moved.translate = Vec3d(0.6, 0, 0);
    moved.scale = Vec3d(0.8);
    const VolumeSet s = voxelized("sphere.obj", voxel), d = voxelized("cube.obj", voxel, moved);
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const auto p = pair(FeatureType::Box, element(Vec3d(0.0)),
                        element(Vec3d(0.6, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0.8)));
    const Morpher morpher(s, d, {p}, WarpSpec{}, blend);
    const VolumeSet mid = morpher.frame(0.5);
    const Mesh surface = surfaceMesh(mid);
    EXPECT_TRUE(surface.report.watertight());
    EXPECT_TRUE(surface.report.consistentlyOriented());
    EXPECT_EQ(surface.report.components, 1u);
    double volume = 0.0;
    for (const Vec3I& t : surface.triangles)
        volume += Vec3d(surface.points[t[0]]).dot(Vec3d(surface.points[t[1]]).cross(Vec3d(surface.points[t[2]]))) / 6.0;
    EXPECT_NEAR(volume / (moments(*mid.density).mass * std::pow(voxel, 3)), 1.0, 0.02); // outward, same volume

    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "volmorph_export_test";
    std::filesystem::create_directories(dir);
    writeMesh(surface, dir / "mid.ply");
    const Mesh back = importMesh(dir / "mid.ply");
    EXPECT_EQ(back.triangles.size(), surface.triangles.size());
    EXPECT_TRUE(back.report.watertight());
    ASSERT_TRUE(back.hasColors());
    EXPECT_THROW(writeMesh(surface, dir / "mid.stl"), UserError);
    writeMesh(surface, dir / "mid.obj");
    EXPECT_EQ(importMesh(dir / "mid.obj").triangles.size(), surface.triangles.size());
    size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) files += entry.is_regular_file();
    EXPECT_GE(files, 2u);
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(entry.path().string().find("partial"), std::string::npos) << entry.path();
    std::filesystem::remove_all(dir);
}

namespace {

/// Radius of the ball with the fog's enclosed volume (world units).
double equivalentRadius(const openvdb::FloatGrid& density)
{
    const double volume = moments(density).mass * std::pow(density.voxelSize()[0], 3);
    return std::cbrt(3.0 * volume / (4.0 * M_PI));
}

/// Euler characteristic V - E + F of a closed triangle mesh: 2 - 2 genus per shell.
long eulerCharacteristic(const Mesh& mesh)
{
    std::set<std::pair<uint32_t, uint32_t>> edges;
    for (const Vec3I& t : mesh.triangles)
        for (int i = 0; i < 3; ++i) {
            const uint32_t a = t[i], b = t[(i + 1) % 3];
            edges.insert({std::min(a, b), std::max(a, b)});
        }
    return long(mesh.points.size()) - long(edges.size()) + long(mesh.triangles.size());
}

} // namespace

// Closed form: with exact distances and the identity warp, blending the sdf of concentric spheres of
// radii r0 and r1 gives (1 - t)(|p| - r0) + t(|p| - r1) = |p| - ((1 - t) r0 + t r1): a sphere whose
// radius moves linearly. Distances clamped to a narrow band would instead flip the whole shell
// between the two surfaces at t = 1/2.
TEST(Morph, SdfModeShrinksConcentricSpheresLinearly)
{
    const double voxel = 0.01;
    ObjectTransform half;
    half.scale = Vec3d(0.5);
    const VolumeSet big = voxelized("sphere.obj", voxel), small = voxelized("sphere.obj", voxel, half);
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const Morpher morpher(big, small, {}, WarpSpec{}, blend);
    const double r0 = equivalentRadius(*morpher.frame(0.0).density);
    const double r1 = equivalentRadius(*morpher.frame(1.0).density);
    EXPECT_NEAR(r0, 2.0 * r1, 2.0 * voxel);
    for (double t : {0.2, 0.4, 0.5, 0.6, 0.8}) {
        const VolumeSet frame = morpher.frame(t);
        const double expected = (1.0 - t) * r0 + t * r1;
        EXPECT_NEAR(equivalentRadius(*frame.density), expected, 0.5 * voxel) << "t = " << t;
        // The rebuilt band holds distances (closed form: |p| - r) all across it.
        double worst = 0.0;
        for (auto it = frame.sdf->cbeginValueOn(); it; ++it)
            worst = std::max(worst, std::abs(double(*it) - (frame.sdf->indexToWorld(it.getCoord()).length() - expected)));
        EXPECT_LE(worst / voxel, 0.5) << "t = " << t; // measured: 0.24 to 0.36
    }
}

// A genus change (sphere, genus 0, into the knot, genus 1) in sdf mode: at every frame the in-between
// is one closed, consistently oriented surface.
TEST(Morph, SdfModeChangesGenusWithOneClosedSurfacePerFrame)
{
    const double voxel = 0.02;
    const VolumeSet sphere = voxelized("sphere.obj", voxel), knot = voxelized("knot1.off", voxel);
    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    const Morpher morpher(sphere, knot, {}, WarpSpec{}, blend);
    for (int f = 0; f <= 12; ++f) {
        const Mesh surface = surfaceMesh(morpher.frame(f / 12.0));
        ASSERT_FALSE(surface.triangles.empty()) << "frame " << f;
        EXPECT_TRUE(surface.report.watertight()) << "frame " << f;
        EXPECT_TRUE(surface.report.consistentlyOriented()) << "frame " << f;
        EXPECT_EQ(surface.report.components, 1u) << "frame " << f;
        if (f == 0) {
            EXPECT_EQ(eulerCharacteristic(surface), 2) << "the sphere has genus 0";
        }
        if (f == 12) {
            EXPECT_EQ(eulerCharacteristic(surface), 0) << "the knot has genus 1";
        }
    }
}

// The default scene's in-betweens are one closed surface each and change their enclosed volume
// smoothly. Bound: no step between
// consecutive frames exceeds 3 times the mean step |V(last) - V(first)| / (frames - 1). The blended
// surface moves at a speed that varies with the local distance between the two surfaces (measured:
// at most 1.9 times the mean at this resolution); a snap moves a large part of the volume in one
// frame (the narrow-band blend did: about half the total change at t = 1/2, some 11 times the mean).
TEST(Morph, SdfModeDefaultSceneIsOneSurfaceChangingSmoothly)
{
    Scene scene = loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
    scene.volume.voxelSize = 0.012; // coarser than the scene's 0.008, to keep the test short
    const SceneVolumes volumes = voxelizeScene(scene);
    const Morpher morpher(volumes.source, volumes.target, scene.pairs, scene.warp, scene.blend);
    std::vector<double> v;
    for (int f = scene.frames.first; f <= scene.frames.last; ++f) {
        const VolumeSet frame = morpher.frame(scene.frames.t(f));
        v.push_back(moments(*frame.density).mass * std::pow(frame.density->voxelSize()[0], 3));
        const Mesh surface = surfaceMesh(frame);
        EXPECT_TRUE(surface.report.watertight()) << "frame " << f;
        EXPECT_EQ(surface.report.components, 1u) << "frame " << f;
    }
    const double mean = std::abs(v.back() - v.front()) / double(v.size() - 1);
    ASSERT_GT(mean, 0.0);
    double worst = 0.0;
    for (size_t i = 0; i + 1 < v.size(); ++i) worst = std::max(worst, std::abs(v[i + 1] - v[i]) / mean);
    std::printf("largest volume step: %.2f times the mean\n", worst);
    for (size_t i = 0; i + 1 < v.size(); ++i)
        EXPECT_LE(std::abs(v[i + 1] - v[i]), 3.0 * mean) << "between frames " << scene.frames.first + int(i)
                                                         << " and " << scene.frames.first + int(i) + 1;
}

// Dust removal (blend.min_island) in sdf mode, on a shape built by OpenVDB's own level-set tools:
// a ball of radius 0.3 with a cavity of radius 1.5 voxels at its centre, and apart from it a speck
// of radius 1.5 voxels (19 voxel centres inside each, fewer than the default 27). With identical
// sides the blend is the shape itself: the speck must go and the cavity be filled; with
// min_island 0 both stay.
TEST(Morph, SdfModeDropsSpecksAndFillsBubbles)
{
    namespace tools = openvdb::tools;
    const float voxel = 0.01f, width = 3.0f;
    auto sphere = [&](float radius, const openvdb::Vec3f& centre) {
        return tools::createLevelSetSphere<openvdb::FloatGrid>(radius, centre, voxel, width);
    };
    openvdb::FloatGrid::Ptr shape = sphere(0.3f, openvdb::Vec3f(0.0f));
    tools::csgDifference(*shape, *sphere(1.5f * voxel, openvdb::Vec3f(0.0f)));
    tools::csgUnion(*shape, *sphere(1.5f * voxel, openvdb::Vec3f(0.5f, 0.0f, 0.0f)));
    VolumeSet side;
    side.sdf = shape;
    side.density = fogFromLevelSet(*shape, 1.5f * voxel);
    side.color = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.5f));
    side.color->setTransform(shape->transform().copy());
    const openvdb::Coord speck(50, 0, 0), cavity(0, 0, 0);
    ASSERT_LT(shape->tree().getValue(speck), 0.0f);
    ASSERT_GT(shape->tree().getValue(cavity), 0.0f);

    BlendSpec blend;
    blend.mode = BlendMode::Sdf;
    ASSERT_EQ(blend.minIslandVoxels, 27);
    const VolumeSet cleaned = Morpher(side, side, {}, WarpSpec{}, blend).frame(0.5);
    EXPECT_GT(cleaned.sdf->tree().getValue(speck), 0.0f) << "the speck is dust";
    EXPECT_LT(cleaned.sdf->tree().getValue(cavity), 0.0f) << "the cavity is a bubble";
    EXPECT_EQ(surfaceMesh(cleaned).report.components, 1u);

    blend.minIslandVoxels = 0;
    const VolumeSet kept = Morpher(side, side, {}, WarpSpec{}, blend).frame(0.5);
    EXPECT_LT(kept.sdf->tree().getValue(speck), 0.0f);
    EXPECT_GT(kept.sdf->tree().getValue(cavity), 0.0f);
    EXPECT_EQ(surfaceMesh(kept).report.components, 3u);
}
