// The Morpher: closed forms of simple pairs (translation, rotation, scale), the ends, and the
// sparse domain against dense references.
#include "support/WarpFixtures.h"

#include <volmorph/Scene.h>

using namespace volmorph;
using namespace volmorph::test;

TEST(Morph, PointPairTranslatesTheSphereLinearly)
{
    const double voxel = 0.04;
    const VolumeSet s = voxelized("sphere.obj", voxel),
                    d = voxelized("sphere.obj", voxel, placed(Vec3d(1, 0, 0)));
    const Morpher morpher(s, d,
                          {pair(FeatureType::Point, element(Vec3d(0.0)), element(Vec3d(1, 0, 0)))},
                          WarpSpec{}, BlendSpec{});
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
    const OnePairMorph bar = turningBar(voxel);
    const Morpher morpher(bar.source, bar.target, {bar.pair}, WarpSpec{}, BlendSpec{});
    const Moments m = moments(*morpher.frame(0.5).density);
    const double angle = 0.5 * std::atan2(2.0 * m.ixy, m.ixx - m.iyy);
    EXPECT_NEAR(angle * 180.0 / M_PI, 45.0, 0.5);
    EXPECT_NEAR(m.mass * std::pow(voxel, 3), 0.09,
                0.09 * 0.02); // the bar's volume (1 x 0.3 x 0.3) is kept
}

TEST(Morph, ScalingPairScalesTheVolumeCubically)
{
    // Both sides warped to the same sphere scaled by 1 + t, in either blend mode.
    const OnePairMorph sphere = doublingSphere(0.02);
    const double v0 = moments(*sphere.source.density).mass;
    for (BlendMode mode : {BlendMode::Density, BlendMode::Sdf}) {
        BlendSpec blend;
        blend.mode = mode;
        const Morpher morpher(sphere.source, sphere.target, {sphere.pair}, WarpSpec{}, blend);
        for (double t : {0.25, 0.5, 0.75}) {
            const double scale = 1.0 + t;
            EXPECT_NEAR(moments(*morpher.frame(t).density).mass / v0, scale * scale * scale,
                        0.02 * scale * scale * scale)
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
    for (double t : {0.0, 0.3, 0.7, 1.0})
        EXPECT_LT(maxDifference(*morpher.frame(t).density, *s.density), 1e-5) << t;
}

TEST(Morph, EndsAreSourceAndTarget)
{
    const auto [s, d] = defaultSceneObjects(0.02);
    const Scene scene =
        loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
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
    return voxelized("cube.obj", voxel, placed(translate, 0.7));
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
            for (auto& p :
                 pairs) { // world units here: origins and scales inside the objects' region
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
            const std::string where = std::string(mode == BlendMode::Sdf ? "sdf" : "density") +
                                      " trial " + std::to_string(trial);
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
            worstColor =
                std::max(worstColor, double((*it - denseColor.getValue(it.getCoord())).length()));
        EXPECT_EQ(worstColor, 0.0) << where;
        if (firstSamples == 0) firstSamples = sparseStats.blendSamples;
    }
    // The last frame repeats the first: every distance it needs is kept, none is sampled again.
    MorphStats again;
    morpher.frame(0.5, &again);
    EXPECT_LT(again.blendSamples, firstSamples / 4);
}

TEST(Morph, DensityInteriorsAreTilesOfTheValuesSamplingGives)
{
    // Density mode keeps a leaf whose points all warp into blocks of one value on both sides as a
    // tile (UniformBlocks.h). The same morph of sides whose tiles were made voxels samples every
    // point: the frames agree voxel for voxel, bit for bit.
    const OnePairMorph sphere = doublingSphere(0.02); // radius 25 voxels: interior blocks
    auto voxelized = [](const VolumeSet& v) {
        VolumeSet out = v;
        out.density = v.density->deepCopy();
        out.density->tree().voxelizeActiveTiles();
        out.color = v.color->deepCopy();
        out.color->tree().voxelizeActiveTiles();
        return out;
    };
    BlendSpec blend;
    blend.mode = BlendMode::Density;
    const Morpher tiled(sphere.source, sphere.target, {sphere.pair}, WarpSpec{}, blend);
    const Morpher sampled(voxelized(sphere.source), voxelized(sphere.target), {sphere.pair},
                          WarpSpec{}, blend);
    for (double t : {0.3, 0.7}) {
        MorphStats a, b;
        const VolumeSet x = tiled.frame(t, &a), y = sampled.frame(t, &b);
        // The interior's blocks (50 at t = 0.3, 128 at t = 0.7) became tiles, not leaves.
        EXPECT_GE(b.outputLeaves, a.outputLeaves + 40) << "t " << t;
        EXPECT_EQ(a.activeVoxels, b.activeVoxels) << "t " << t;
        auto xd = x.density->getConstAccessor();
        auto xc = x.color->getConstAccessor();
        auto yc = y.color->getConstAccessor();
        size_t differ = 0;
        for (auto it = y.density->cbeginValueOn(); it; ++it) {
            const openvdb::Coord c =
                it.getBoundingBox().min(); // a tile's first voxel stands for it
            differ +=
                !(xd.isValueOn(c) && xd.getValue(c) == *it && xc.getValue(c) == yc.getValue(c));
        }
        EXPECT_EQ(differ, 0u) << "t " << t;
    }
}

TEST(Morph, WithPairsKeepsTheSetupAndGivesANewMorphersFrames)
{
    // What the editor does after a drag: the same sides, one pair moved. The Morpher made by
    // withPairs (sharing the sdf mode's extended distances) and one built from scratch with the
    // moved pairs give the same frames, value for value; the move shows.
    const auto [s, d] = defaultSceneObjects(0.02);
    const Scene scene =
        loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
    ASSERT_EQ(scene.blend.mode, BlendMode::Sdf);
    const Morpher first(s, d, scene.pairs, scene.warp, scene.blend);
    std::vector<FeaturePairSpec> moved = scene.pairs;
    moved[1].target.origin += Vec3d(0.08, 0.0, 0.0);
    const Morpher edited = first.withPairs(moved);
    const Morpher fresh(s, d, moved, scene.warp, scene.blend);
    for (const double t : {0.3, 0.6}) {
        const VolumeSet a = edited.frame(t), b = fresh.frame(t);
        EXPECT_EQ(a.density->activeVoxelCount(), b.density->activeVoxelCount()) << t;
        EXPECT_EQ(maxDifference(*a.sdf, *b.sdf), 0.0) << t;
        EXPECT_EQ(maxDifference(*a.density, *b.density), 0.0) << t;
    }
    EXPECT_GT(maxDifference(*first.frame(0.6).density, *edited.frame(0.6).density), 0.05);
    // No pairs: set up anew (the identity warp's own setup), as a Morpher built without them.
    const VolumeSet none = first.withPairs({}).frame(0.6);
    const VolumeSet built = Morpher(s, d, {}, scene.warp, scene.blend).frame(0.6);
    EXPECT_EQ(maxDifference(*none.sdf, *built.sdf), 0.0);
}
