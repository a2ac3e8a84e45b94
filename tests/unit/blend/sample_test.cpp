// The blend's trilinear read (blend/Sample.h) against OpenVDB's BoxSampler: the same bits at every
// kind of position (inside a leaf, straddling two, four or eight leaves, over tiles and empty
// space).
#include "blend/Sample.h" // private to the library; tested directly

#include <openvdb/openvdb.h>

#include <gtest/gtest.h>

#include <cstring>
#include <random>

namespace {

/// A float grid with leaves of random values, a gap, and an active tile, around the origin.
openvdb::FloatGrid::Ptr patchwork()
{
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(-0.25f);
    std::mt19937 random(7);
    std::uniform_real_distribution<float> value(-1.0f, 1.0f);
    auto acc = grid->getAccessor();
    for (auto c = openvdb::CoordBBox(openvdb::Coord(-12), openvdb::Coord(19)).begin(); c; ++c)
        if ((*c).x() < 10 || (*c).y() > -4) acc.setValue(*c, value(random));
    grid->tree().addTile(1, openvdb::Coord(24, 0, 0), 0.75f, true); // an 8^3 tile beside them
    return grid;
}

template <typename GridT>
void expectSameBits(const GridT& grid, const openvdb::Vec3R& p)
{
    auto fast = grid.getConstAccessor(), reference = grid.getConstAccessor();
    const auto a = volmorph::detail::sample<openvdb::tools::BoxSampler>(fast, p);
    const auto b = openvdb::tools::BoxSampler::sample(reference, p);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "at " << p;
}

} // namespace

TEST(Sample, BoxReadsGiveBoxSamplersBitsEverywhere)
{
    const openvdb::FloatGrid::Ptr grid = patchwork();
    std::mt19937 random(11);
    std::uniform_real_distribution<double> u(-14.0, 34.0), frac(0.0, 1.0);
    for (int i = 0; i < 20000; ++i)
        expectSameBits(*grid, openvdb::Vec3R(u(random), u(random), u(random)));
    // Cells straddling one, two and three leaf faces, at leaf corners.
    for (int x : {7, 15, -1, -9})
        for (int y : {3, 7, -1})
            for (int z : {7, 23, 2})
                expectSameBits(
                    *grid, openvdb::Vec3R(x + frac(random), y + frac(random), z + frac(random)));
}
