// Per-thread readers of the grids a ray samples: the density's cells (from padded leaf copies, so a
// cell's eight corners are eight loads) and the colour grid, both remembering the last 8^3 block.
#pragma once

#include <volmorph/core/Math.h>

#include <openvdb/openvdb.h>
#include <openvdb/math/Ray.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/RayIntersector.h>

#include <algorithm>
#include <limits>
#include <unordered_map>
#include <vector>

namespace volmorph::render {

using openvdb::Coord;
using VdbRay = openvdb::math::Ray<double>;
/// Empty-space skipping: OpenVDB's hierarchical DDA over rayMask()'s topology.
using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::BoolGrid>;

/// Where a trilinear sample of `density` can be non-zero: its active voxels and tiles, dilated by
/// one voxel. (VolumeRayIntersector's own dilation ignores tiles, so a tile on a volume's boundary
/// would lose the half voxel of ramp outside it.)
openvdb::BoolGrid::Ptr rayMask(const openvdb::FloatGrid& density, bool levelSet);

/// Trilinear interpolation of eight colours at local coordinates u in [0, 1]^3.
inline Vec3d trilinear(const openvdb::Vec3s (&v)[2][2][2], const Vec3d& u)
{
    const double x1 = u.x(), y1 = u.y(), z1 = u.z(), x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
    const double w[8] = {x0 * y0 * z0, x0 * y0 * z1, x0 * y1 * z0, x0 * y1 * z1,
                         x1 * y0 * z0, x1 * y0 * z1, x1 * y1 * z0, x1 * y1 * z1};
    const openvdb::Vec3s* c = &v[0][0][0];
    double r = 0.0, g = 0.0, b = 0.0;
    for (int i = 0; i < 8; ++i) {
        r += w[i] * c[i].x();
        g += w[i] * c[i].y();
        b += w[i] * c[i].z();
    }
    return Vec3d(r, g, b);
}

/// Each leaf's values plus one more layer on its +x, +y and +z sides (read from the neighbours):
/// the eight corners of every cell whose origin lies in the leaf, so that reading them is eight
/// loads, also for cells that straddle two, four or eight leaves. A leaf whose 512 values are equal
/// is left out: readers treat it as a tile of that value (interpolation reads values, never active
/// states), which walkCells crosses in one piece.
class PaddedLeaves {
public:
    using Leaf = openvdb::FloatTree::LeafNodeType;
    static constexpr int kSide = Leaf::DIM + 1, kSize = kSide * kSide * kSide;

    /// Copies every non-constant leaf of `tree` with its padding, in parallel.
    explicit PaddedLeaves(const openvdb::FloatTree& tree);

    const float* find(const Leaf* leaf) const
    {
        const auto it = mIndex.find(leaf);
        return it == mIndex.end() ? nullptr : it->second;
    }

private:
    std::vector<float> mValues;
    std::unordered_map<const Leaf*, const float*> mIndex;
};

/// One thread's trilinear reader of a colour grid, remembering the last 8^3 block: inside a block
/// without a leaf the colour is its tile value, inside a leaf the corners are read from its buffer.
struct ColorReader {
    using Tree = openvdb::Vec3STree;
    using Leaf = Tree::LeafNodeType;
    openvdb::tree::ValueAccessor<const Tree> acc;
    Coord block{std::numeric_limits<int>::max()};
    const Leaf* leaf = nullptr;
    openvdb::Vec3s tile;

    explicit ColorReader(const Tree& tree) : acc(tree) {}

    Vec3d at(const Vec3d& ip)
    {
        const Coord c = Coord::floor(ip);
        const Coord b(c.x() & ~7, c.y() & ~7, c.z() & ~7);
        if (b != block) {
            block = b;
            leaf = acc.probeConstLeaf(c);
            if (!leaf) tile = acc.getValue(c);
        }
        openvdb::Vec3s v[2][2][2];
        if ((c.x() & 7) != 7 && (c.y() & 7) != 7 && (c.z() & 7) != 7) {
            if (!leaf) return Vec3d(tile.x(), tile.y(), tile.z());
            const openvdb::Vec3s* d = leaf->buffer().data() + Leaf::coordToOffset(c);
            v[0][0][0] = d[0];
            v[0][0][1] = d[1];
            v[0][1][0] = d[8];
            v[0][1][1] = d[9];
            v[1][0][0] = d[64];
            v[1][0][1] = d[65];
            v[1][1][0] = d[72];
            v[1][1][1] = d[73];
        } else {
            openvdb::tools::BoxSampler::getValues(v, acc, c);
        }
        return trilinear(v, ip - Vec3d(c.x(), c.y(), c.z()));
    }
};

/// One thread's reader of a cell's eight density values: the padded copy of the cell's leaf, or the
/// one value of a block that has none (a tile, the background, or a constant leaf).
struct DensityReader {
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc;
    const PaddedLeaves& padded;
    /// A direct-mapped cache of 8^3 blocks: a block's padded values, or its one value if it has
    /// none.
    struct Block {
        Coord origin{std::numeric_limits<int>::max()};
        const float* values = nullptr;
        float tile = 0.0f;
    };
    Block cache[64];
    float tile = 0.0f; ///< the value of the last cell's block, when cell() returned false

    DensityReader(const openvdb::FloatTree& tree, const PaddedLeaves& p) : acc(tree), padded(p) {}

    const Block& blockAt(const Coord& b) // b: a block origin (multiples of 8)
    {
        Block& e =
            cache[((b.x() >> 3) & 3) | (((b.y() >> 3) & 3) << 2) | (((b.z() >> 3) & 3) << 4)];
        if (e.origin != b) {
            e.origin = b;
            const PaddedLeaves::Leaf* leaf = acc.probeConstLeaf(b);
            e.values = leaf ? padded.find(leaf) : nullptr;
            if (!e.values) e.tile = acc.getValue(b);
        }
        return e;
    }

    /// Fills `v` for the cell at `c` and returns true, or returns false (filling nothing, `tile`
    /// set) if c's block has one value and c lies inside it (not on its +x, +y or +z face layer).
    bool cell(const Coord& c, float (&v)[2][2][2])
    {
        const Coord b(c.x() & ~7, c.y() & ~7, c.z() & ~7);
        const Block& own = blockAt(b);
        if (own.values) {
            constexpr int s = PaddedLeaves::kSide;
            const float* p = own.values + ((c.x() & 7) * s + (c.y() & 7)) * s + (c.z() & 7);
            v[0][0][0] = p[0];
            v[0][0][1] = p[1];
            v[0][1][0] = p[s];
            v[0][1][1] = p[s + 1];
            v[1][0][0] = p[s * s];
            v[1][0][1] = p[s * s + 1];
            v[1][1][0] = p[s * s + s];
            v[1][1][1] = p[s * s + s + 1];
            return true;
        }
        tile = own.tile;
        const int edge[3] = {(c.x() & 7) == 7, (c.y() & 7) == 7, (c.z() & 7) == 7};
        if (!edge[0] && !edge[1] && !edge[2]) return false;
        // A cell straddling blocks: each corner from its own block (a tile value, or a leaf value).
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j)
                for (int k = 0; k < 2; ++k) {
                    const Coord corner = c.offsetBy(i, j, k);
                    const Block& e =
                        blockAt(Coord(corner.x() & ~7, corner.y() & ~7, corner.z() & ~7));
                    v[i][j][k] = e.values ? acc.getValue(corner) : e.tile;
                }
        return true;
    }
};

} // namespace volmorph::render
