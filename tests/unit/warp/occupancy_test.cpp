// The occupancy of the warp's domain test (warp/Occupancy.h) against the tree it summarises.
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;

TEST(AdaptiveWarp, OccupancyBoxQueriesMatchTheTree)
{
    // Occupancy answers box queries from a summed-volume table; the tree, scanned block by block,
    // is the reference.
    openvdb::FloatTree tree(0.0f);
    std::mt19937 random(7);
    std::uniform_int_distribution<int> coord(-200, 200);
    for (int i = 0; i < 3000; ++i)
        tree.setValue(openvdb::Coord(coord(random), coord(random), coord(random)), 1.0f);
    tree.fill(openvdb::CoordBBox(openvdb::Coord(256), openvdb::Coord(256 + 127)), 1.0f,
              true); // a tile
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
