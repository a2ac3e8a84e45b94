// The deep shadow maps (render/src/Shadows.h, PointShadowMap.h) against the exact transmittance,
// marched cell by cell from each point toward the light (what shadow_cache = 0 renders with).
#include <volmorph/Voxelize.h>

#include "PointShadowMap.h"
#include "Shadows.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>

using namespace volmorph;
using namespace volmorph::render;

namespace {

const std::filesystem::path kMeshes =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";

struct Errors {
    double mean = 0.0, max = 0.0;
    int shadowed = 0; ///< points whose exact transmittance is below 0.9
};

/// Compares a light's deep shadow map (at 1-voxel spacing) with exact marches at random points of
/// the sphere's box. A directional light (w = 0) shines from direction `light`, a point light
/// (w = 1) is at `light`.
Errors compare(const openvdb::FloatGrid& density, const Vec3d& light, double w, double sigma,
               int points)
{
    const double sigmaPerVoxel = sigma * density.voxelSize()[0];
    const PaddedLeaves padded(density.tree());
    const openvdb::BoolGrid::Ptr mask = rayMask(density, false);
    const MarchInputs in{density, padded, *mask, false, sigmaPerVoxel, nullptr};
    std::unique_ptr<PointShadowMap> point;
    std::unique_ptr<ShadowMap> parallel;
    if (w > 0.0)
        point = std::make_unique<PointShadowMap>(in, light, density.voxelSize()[0]);
    else
        parallel = std::make_unique<ShadowMap>(in, -light, density.voxelSize()[0]);
    Intersector inter(*mask);
    DensityReader acc(density.tree(), padded);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coordinate(-0.55, 0.55);
    Errors e;
    for (int n = 0; n < points; ++n) {
        const Vec3d p(coordinate(rng), coordinate(rng), coordinate(rng));
        Vec3d toward = w > 0.0 ? light - p : light * 1e3;
        const double distance = toward.length();
        toward /= distance;
        const Vec3d ip = density.worldToIndex(p);
        const double exact =
            std::exp(-opticalDepth(inter, false, acc, p, toward, distance, sigmaPerVoxel));
        const double error = std::abs((point ? point->lookup(ip) : parallel->lookup(ip)) - exact);
        e.mean += error / points;
        e.max = std::max(e.max, error);
        e.shadowed += exact < 0.9;
    }
    return e;
}

} // namespace

TEST(Shadows, PointLightMapMatchesTheExactMarch)
{
    VoxelizeOptions o;
    o.resolution = 64;
    const VolumeSet sphere = voxelize(importMesh(kMeshes / "sphere.obj"), o); // radius 0.5
    const double sigma = 4.0; // per world unit: optical depth 4 across the sphere
    // Outside, on one face's axis; across a cube map's edge and corner (the sphere spans three
    // faces); inside the sphere, where every face sees it.
    const Vec3d lights[] = {Vec3d(1.6, 0.2, -0.1), Vec3d(0.8, 0.75, 0.7), Vec3d(0.1, -0.05, 0.07)};
    for (const Vec3d& light : lights) {
        const Errors e = compare(*sphere.density, light, 1.0, sigma, 20000);
        SCOPED_TRACE(::testing::Message() << "light at " << light);
        EXPECT_GT(e.shadowed, 2000); // the comparison covers shadowed points
        EXPECT_LT(e.mean, 1e-3);     // measured 0.5e-3, 0.24e-3 and 0.06e-3
        EXPECT_LT(e.max, 0.025);     // 0.012, 0.005 and 0.0008
    }
}

TEST(Shadows, DirectionalLightMapMatchesTheExactMarch)
{
    VoxelizeOptions o;
    o.resolution = 64;
    const VolumeSet sphere = voxelize(importMesh(kMeshes / "sphere.obj"), o);
    for (const Vec3d& toward : {Vec3d(0, 1, 0), Vec3d(0.6, 0.7, -0.3).unit()}) {
        const Errors e = compare(*sphere.density, toward, 0.0, 4.0, 20000);
        SCOPED_TRACE(::testing::Message() << "light toward " << toward);
        EXPECT_GT(e.shadowed, 2000);
        EXPECT_LT(e.mean, 1.5e-3); // measured 0.7e-3 and 1.0e-3
        EXPECT_LT(e.max, 0.04);    // 0.021 and 0.029
    }
}
