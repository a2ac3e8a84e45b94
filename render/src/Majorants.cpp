#include "Majorants.h"

#include <algorithm>
#include <limits>

namespace volmorph::render {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

/// The density a value stands for.
float densityOf(float value, bool levelSet)
{
    return levelSet ? (value < 0.0f ? 1.0f : 0.0f) : std::max(0.0f, value);
}

/// The largest density of each block alone (its leaf's values, padded or constant, or its tile's
/// value), in block coordinates.
openvdb::FloatTree blockMaxima(const openvdb::FloatTree& tree, const PaddedLeaves& padded,
                               bool levelSet)
{
    openvdb::FloatTree blocks(0.0f);
    openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(blocks);
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        const float* values = padded.find(&*leaf);
        float top = 0.0f;
        if (values) {
            for (int i = 0; i < PaddedLeaves::kSize; ++i)
                top = std::max(top, densityOf(values[i], levelSet));
        } else {
            top = densityOf(leaf->getFirstValue(), levelSet);
        }
        if (top > 0.0f) acc.setValue(leaf->origin() >> 3, top);
    }
    // Tiles, active or not (a level set's inside is an inactive negative tile), split into blocks.
    auto it = tree.cbeginValueAll();
    it.setMaxDepth(openvdb::FloatTree::DEPTH - 2); // above the leaves
    for (; it; ++it) {
        if (it.isVoxelValue()) continue;
        const float top = densityOf(*it, levelSet);
        if (top <= 0.0f) continue;
        CoordBBox box;
        it.getBoundingBox(box);
        const CoordBBox blocksBox(box.min() >> 3, box.max() >> 3);
        for (auto b = blocksBox.begin(); b; ++b) acc.setValue(*b, top);
    }
    return blocks;
}

} // namespace

Majorants::Majorants(const openvdb::FloatGrid& density, const PaddedLeaves& padded, bool levelSet)
{
    const openvdb::FloatTree own = blockMaxima(density.tree(), padded, levelSet);
    // A block's points read one layer of its +x, +y, +z neighbours: each block's value reaches the
    // seven blocks on its -x, -y, -z sides.
    openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(mBlocks);
    for (auto it = own.cbeginValueOn(); it; ++it) {
        const Coord b = it.getCoord();
        for (int dx = 0; dx < 2; ++dx)
            for (int dy = 0; dy < 2; ++dy)
                for (int dz = 0; dz < 2; ++dz) {
                    const Coord c = b.offsetBy(-dx, -dy, -dz);
                    acc.setValue(c, std::max(acc.getValue(c), *it));
                }
    }
    mBlocks.evalActiveVoxelBoundingBox(mBounds);
}

MajorantWalk::MajorantWalk(const Majorants& majorants, Majorants::Accessor& acc, const Vec3d& eye,
                           const Vec3d& dir, double t)
    : mAcc(acc), mBlockRay{eye / 8.0, dir / 8.0, false}
{
    // The ray's span inside the blocks' box (index space), by OpenVDB's slab test.
    const CoordBBox& b = majorants.bounds();
    const VdbRay ray(eye, dir, t, std::numeric_limits<double>::max());
    const openvdb::math::BBox<Vec3d> box(b.min().asVec3d() * 8.0,
                                         (b.max().asVec3d() + Vec3d(1.0)) * 8.0);
    if (b.empty() || !ray.intersects(box, mT, mEnd)) mT = mEnd = t;
    if (mT < mEnd) mDda.start(mBlockRay, mT);
}

bool MajorantWalk::next(double& t0, double& t1, float& majorant)
{
    if (mT >= mEnd) return false;
    const int a = mDda.axis();
    t0 = mT;
    t1 = std::min(mDda.next[a], mEnd);
    majorant = mAcc.getValue(Coord(mDda.cell[0], mDda.cell[1], mDda.cell[2]));
    mT = t1;
    mDda.advance(a);
    return true;
}

} // namespace volmorph::render
