#include "Occupancy.h"

namespace volmorph::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

/// Block coordinates: floor division by 8 (an arithmetic shift, also below zero), as in anyIn.
inline int block(int v)
{
    return v >> 3;
}

} // namespace

Occupancy::Occupancy(const openvdb::FloatTree& tree)
{
    openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(mBlocks);
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf)
        if (!leaf->isEmpty())
            acc.setValueOn(Coord(block(leaf->origin().x()), block(leaf->origin().y()),
                                 block(leaf->origin().z())));
    auto tiles = tree.cbeginValueOn();
    tiles.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1); // tiles only, not voxels
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        const CoordBBox b = tiles.getBoundingBox();
        mBlocks.fill(CoordBBox(Coord(block(b.min().x()), block(b.min().y()), block(b.min().z())),
                               Coord(block(b.max().x()), block(b.max().y()), block(b.max().z()))),
                     true, true);
    }

    CoordBBox b;
    if (!mBlocks.evalActiveVoxelBoundingBox(b)) return;
    const Coord dim = b.dim();
    constexpr uint64_t kMaxTable = uint64_t(1) << 23; // 32 MiB of counts
    if (uint64_t(dim.x() + 1) * uint64_t(dim.y() + 1) * uint64_t(dim.z() + 1) > kMaxTable) return;
    mLo = b.min();
    mDim = dim;
    const size_t sy = size_t(dim.z() + 1), sx = sy * size_t(dim.y() + 1);
    mPrefix.assign(sx * size_t(dim.x() + 1), 0);
    for (auto it = mBlocks.cbeginValueOn(); it; ++it)
        for (auto c = it.getBoundingBox().begin(); c; ++c) {
            const Coord l = *c - mLo;
            mPrefix[size_t(l.x() + 1) * sx + size_t(l.y() + 1) * sy + size_t(l.z() + 1)] = 1;
        }
    for (int x = 1; x <= dim.x(); ++x)
        for (int y = 1; y <= dim.y(); ++y)
            for (int z = 1; z <= dim.z(); ++z) {
                uint32_t* p = &mPrefix[size_t(x) * sx + size_t(y) * sy + size_t(z)];
                *p += p[-ptrdiff_t(sx)] + p[-ptrdiff_t(sy)] + p[-1] - p[-ptrdiff_t(sx + sy)] -
                      p[-ptrdiff_t(sx + 1)] - p[-ptrdiff_t(sy + 1)] + p[-ptrdiff_t(sx + sy + 1)];
            }
}

bool Occupancy::scan(const Coord& lo, const Coord& hi) const
{
    if (CoordBBox(lo, hi).volume() > (1u << 16)) return true; // too large to be worth asking
    openvdb::tree::ValueAccessor<const openvdb::MaskTree> acc(mBlocks);
    for (int x = lo.x(); x <= hi.x(); ++x)
        for (int y = lo.y(); y <= hi.y(); ++y)
            for (int z = lo.z(); z <= hi.z(); ++z)
                if (acc.isValueOn(Coord(x, y, z))) return true;
    return false;
}

CoordBBox Occupancy::bounds() const
{
    CoordBBox b;
    if (!mBlocks.evalActiveVoxelBoundingBox(b)) return CoordBBox();
    const Coord lo = b.min(), hi = b.max();
    return CoordBBox(Coord(lo.x() * 8, lo.y() * 8, lo.z() * 8),
                     Coord(hi.x() * 8 + 7, hi.y() * 8 + 7, hi.z() * 8 + 7));
}

} // namespace volmorph::detail
