// suggestPairs (volmorph/PairSuggest.h) where principal axes are not the shape's own: a sphere's
// spreads are alike along every axis, a cube's too, so the eigen solver's axes for them are
// arbitrary; the suggested box pair must then not turn the sphere on its way to the cube (each axis
// of both boxes along a world axis), and a box whose one axis is its own (a long box) keeps it.
#include <volmorph/PairSuggest.h>
#include <volmorph/SceneVolumes.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace volmorph;

namespace {

const std::filesystem::path kRoot = VOLMORPH_SOURCE_DIR;

/// The largest |component| of a unit vector: 1 when it lies along a world axis.
double alongWorldAxis(const Vec3d& v)
{
    return std::max({std::abs(v.x()), std::abs(v.y()), std::abs(v.z())});
}

SceneVolumes volumes(const Vec3d& targetScale)
{
    Scene scene = loadScene(kRoot / "scenes" / "sphere-to-box.toml");
    scene.volume.voxelSize.reset();
    scene.volume.resolution = 48;
    scene.target.transform.scale = targetScale;
    return voxelizeScene(scene);
}

} // namespace

TEST(PairSuggest, AlikeSpreadsDoNotTurnTheBox)
{
    const SceneVolumes v = volumes(Vec3d(0.8));
    const PairSuggestion s = suggestPairs(v.source, v.target);
    ASSERT_FALSE(s.pairs.empty());
    const FeaturePairSpec& box = s.pairs.front();
    ASSERT_EQ(box.type, FeatureType::Box);
    const double oneDegree = 1.0 - std::cos(M_PI / 180.0);
    for (const FeatureElement* e : {&box.source, &box.target})
        for (const Vec3d* axis : {&e->xAxis, &e->yAxis, &e->zAxis})
            EXPECT_GT(alongWorldAxis(*axis), 1.0 - oneDegree) << *axis;
    // The same world axis on both sides: the box map turns nothing.
    EXPECT_GT(std::abs(box.source.xAxis.dot(box.target.xAxis)), 1.0 - oneDegree);
    EXPECT_GT(std::abs(box.source.yAxis.dot(box.target.yAxis)), 1.0 - oneDegree);
}

TEST(PairSuggest, AnAxisOfItsOwnIsKept)
{
    // The cube stretched 3x along z: its longest axis is its own and the box pair maps the
    // sphere's (borrowed) longest axis onto it.
    const SceneVolumes v = volumes(Vec3d(0.4, 0.4, 1.2));
    const PairSuggestion s = suggestPairs(v.source, v.target);
    const FeaturePairSpec& box = s.pairs.front();
    const double oneDegree = 1.0 - std::cos(M_PI / 180.0);
    EXPECT_GT(std::abs(box.target.xAxis.z()), 1.0 - oneDegree) << box.target.xAxis;
    EXPECT_NEAR(box.target.scale.x(), 1.2, 0.05);
    for (const Vec3d* axis : {&box.source.xAxis, &box.source.yAxis, &box.target.yAxis})
        EXPECT_GT(alongWorldAxis(*axis), 1.0 - oneDegree) << *axis;
}
