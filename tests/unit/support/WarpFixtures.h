// Fixtures shared by the unit tests of the feature, warp, morph and export stages: feature pairs,
// voxelized test meshes, moments of a fog, random pair configurations, the approximated warp's
// error against the exact one.
#pragma once

#include <volmorph/Export.h>
#include <volmorph/Feature.h>
#include <volmorph/Morph.h>
#include <volmorph/Voxelize.h>
#include <volmorph/Warp.h>

#include "warp/Stretch.h"      // private to the library; tested directly
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

namespace volmorph::test {

inline const std::filesystem::path kMeshes =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";

inline FeatureElement element(const Vec3d& origin, const Vec3d& x = Vec3d(1, 0, 0),
                              const Vec3d& y = Vec3d(0, 1, 0), const Vec3d& scale = Vec3d(1.0))
{
    FeatureElement e;
    e.origin = origin;
    e.xAxis = x.unit();
    e.yAxis = y.unit();
    e.zAxis = e.xAxis.cross(e.yAxis);
    e.scale = scale;
    return e;
}

inline FeaturePairSpec pair(FeatureType type, const FeatureElement& s, const FeatureElement& t)
{
    FeaturePairSpec p;
    p.type = type;
    p.source = s;
    p.target = t;
    return p;
}

/// A mesh's placement: scaled by `scale` about the origin, then moved by `translate` (world units).
inline ObjectTransform placed(const Vec3d& translate, double scale = 1.0)
{
    ObjectTransform xf;
    xf.translate = translate;
    xf.scale = Vec3d(scale);
    return xf;
}

inline VolumeSet voxelized(const std::string& mesh, double voxelSize,
                           const ObjectTransform& xf = {})
{
    VoxelizeOptions o;
    o.voxelSize = voxelSize;
    return voxelize(importMesh(kMeshes / mesh, xf), o);
}

/// A sphere of `radius` about `centre` as a voxelized object: exact distances (OpenVDB's
/// level-set sphere, a narrow band of `band` voxels), its fog, a grey colour.
inline VolumeSet exactSphere(double radius, double voxel, float band = 3.0f,
                             const Vec3d& centre = Vec3d(0.0))
{
    VolumeSet v;
    v.sdf = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(radius), openvdb::Vec3f(centre), float(voxel), band);
    v.sdf->setName(kSdfGridName);
    v.density = fogFromLevelSet(*v.sdf, 1.5f * float(voxel));
    v.density->setName(kDensityGridName);
    v.color = openvdb::Vec3SGrid::create(Vec3f(0.5f));
    v.color->setTransform(v.sdf->transform().copy());
    v.color->setName(kColorGridName);
    v.color->tree().topologyUnion(v.sdf->tree());
    return v;
}

/// Two objects and the one pair that turns one into the other.
struct OnePairMorph {
    VolumeSet source, target;
    FeaturePairSpec pair;
};
/// A bar along x (1 x 0.3 x 0.3 world units) and the same bar turned a quarter turn about z.
inline OnePairMorph turningBar(double voxelSize)
{
    ObjectTransform bar, turned;
    bar.scale = Vec3d(1.0, 0.3, 0.3);
    turned.scale = Vec3d(1.0, 0.3, 0.3);
    turned.rotateRadians = Vec3d(0, 0, M_PI / 2);
    return {voxelized("cube.obj", voxelSize, bar), voxelized("cube.obj", voxelSize, turned),
            pair(FeatureType::Box,
                 element(Vec3d(0.0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(1, 0.3, 0.3)),
                 element(Vec3d(0.0), Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(1, 0.3, 0.3)))};
}

/// The unit sphere (radius 0.5) and the same sphere scaled by 2 about the origin.
inline OnePairMorph doublingSphere(double voxelSize)
{
    return {voxelized("sphere.obj", voxelSize),
            voxelized("sphere.obj", voxelSize, placed(Vec3d(0.0), 2.0)),
            pair(FeatureType::Box, element(Vec3d(0.0)),
                 element(Vec3d(0.0), Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(2.0)))};
}

/// The default scene's two objects (scenes/bunny-to-knot.toml), voxelized.
struct VolumePair {
    VolumeSet source, target;
};
inline VolumePair defaultSceneObjects(double voxelSize)
{
    return {voxelized("bunny.obj", voxelSize, placed(Vec3d(0.0), 0.1)),
            voxelized("knot1.off", voxelSize, placed(Vec3d(0, 0.5, 0)))};
}

struct Moments {
    double mass = 0.0;
    Vec3d centroid{0.0};
    double ixx = 0, iyy = 0, ixy = 0; ///< central second moments in the xy plane
};

inline Moments moments(const openvdb::FloatGrid& density)
{
    Moments m;
    std::vector<std::pair<Vec3d, double>> samples;
    for (auto it = density.cbeginValueOn(); it; ++it) {
        const openvdb::CoordBBox b = it.getBoundingBox();
        if (it.isVoxelValue()) {
            samples.emplace_back(density.indexToWorld(it.getCoord()), double(*it));
        } else {
            for (auto c = b.begin(); c; ++c)
                samples.emplace_back(density.indexToWorld(*c), double(*it));
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

/// Radius of the ball with the fog's enclosed volume (world units).
inline double equivalentRadius(const openvdb::FloatGrid& density)
{
    const double volume = moments(density).mass * std::pow(density.voxelSize()[0], 3);
    return std::cbrt(3.0 * volume / (4.0 * M_PI));
}

/// The largest |vel - expected(world point)| over the active voxels of `where` whose value
/// passes `keep`, relative to the largest expected speed there; also counts those voxels (and
/// fails the test where one lacks velocity).
template <typename Keep, typename Expected>
double worstVelocityError(const VolumeSet& frame, const openvdb::FloatGrid& where, const Keep& keep,
                          const Expected& expected, int& count)
{
    EXPECT_TRUE(frame.velocity);
    if (!frame.velocity) return 1e9;
    auto vel = frame.velocity->getConstAccessor();
    double worst = 0.0, fastest = 0.0;
    count = 0;
    for (auto it = where.cbeginValueOn(); it; ++it) {
        if (!keep(*it) || !it.isVoxelValue()) continue;
        EXPECT_TRUE(vel.isValueOn(it.getCoord()));
        const Vec3d e = expected(where.indexToWorld(it.getCoord()));
        worst = std::max(worst, (Vec3d(vel.getValue(it.getCoord())) - e).length());
        fastest = std::max(fastest, e.length());
        ++count;
    }
    return worst / fastest;
}

/// Largest |a - b| of two density grids over the union of their active voxels.
inline double maxDifference(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
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
inline Vec3d rotate(const Vec3d& v, const Vec3d& k, double angle)
{
    return v * std::cos(angle) + k.cross(v) * std::sin(angle) +
           k * (k.dot(v) * (1.0 - std::cos(angle)));
}

/// A random configuration of n pairs of random types inside a cube of `extent` units, made the way
/// a user makes them: each target element is its source element moved by up to a quarter of the
/// extent, scaled by 0.6 to 1.6 per axis and turned by up to 60 degrees.
inline std::vector<FeaturePairSpec> randomPairs(std::mt19937& random, int n, double extent)
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
        while (across.length() < 0.1)
            across = s.xAxis.cross(direction()); // a frame, not a near-degenerate one
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
        t.scale =
            Vec3d(s.scale.x() * factor.x(), s.scale.y() * factor.y(), s.scale.z() * factor.z());
        pairs.push_back(p);
    }
    return pairs;
}

/// The largest entry of J and of dW/dt off the reference, relative to the reference's largest.
inline double relativeError(const InverseWarp::Derivatives& a, const InverseWarp::Derivatives& b)
{
    double err = 0.0, size = 0.0;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            err = std::max(err, std::abs(a.jacobian(i, j) - b.jacobian(i, j)));
            size = std::max(size, std::abs(b.jacobian(i, j)));
        }
        err = std::max(err, std::abs(a.rate[i] - b.rate[i]));
        size = std::max(size, std::abs(b.rate[i]));
    }
    return err / size;
}

/// The largest distance between a leaf's approximated points and the exact warp's, on either side,
/// over every `stride`-th voxel.
inline double leafError(const InverseWarp& warp, const detail::WarpLeaf& leaf, int stride)
{
    double local = 0.0;
    Vec3d s, d;
    for (int i = 0; i < 512; i += stride) {
        warp.map(leaf.origin.offsetBy(i >> 6, (i >> 3) & 7, i & 7).asVec3d(), s, d);
        local = std::max(
            {local, (Vec3d(leaf.source(i)) - s).length(), (Vec3d(leaf.target(i)) - d).length()});
    }
    return local;
}

/// The largest leafError over every leaf of the box [0, last]^3 (index space).
inline double largestError(const InverseWarp& warp, const detail::AdaptiveWarp& adaptive, int last,
                           int stride, detail::AdaptiveWarpStats& stats)
{
    std::mutex m;
    double worst = 0.0;
    adaptive.forEachLeaf(
        openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(last)), nullptr, nullptr,
        [&](const detail::WarpLeaf& leaf) {
            const double local = leafError(warp, leaf, stride);
            std::lock_guard<std::mutex> lock(m);
            worst = std::max(worst, local);
        },
        &stats);
    return worst;
}

} // namespace volmorph::test
