// The majorant grid of null-scattering path tracing (as pbrt-v4's MajorantGrid, here built from the
// VDB tree): one value per 8^3 block of the density grid, at least the density anywhere a trilinear
// sample inside that block can reach, and the walk of a ray through those blocks.
#pragma once

#include "Cell.h"
#include "CellWalk.h"
#include "GridReaders.h"

#include <openvdb/openvdb.h>

namespace volmorph::render {

/// Block (i, j, k) of the majorant grid covers the index-space points [8i, 8i + 8)^3 of the density
/// grid. A trilinear sample at such a point reads the voxels [8i, 8i + 8]^3: the block and one
/// layer of its +x, +y and +z neighbours, so a block's majorant is the largest density over the
/// block and those seven neighbours (negative fog densities count as 0; a level set's density is 1
/// where its distance is negative). Dense inside the density's tree: its tiles are split into
/// blocks (a 128^3 tile, the largest a volmorph grid has, is 4096 blocks).
class Majorants {
public:
    Majorants(const openvdb::FloatGrid& density, const PaddedLeaves& padded, bool levelSet);

    /// The majorant density of the block at block coordinates `block` (index >> 3).
    using Accessor = openvdb::tree::ValueAccessor<const openvdb::FloatTree>;
    Accessor accessor() const { return Accessor(mBlocks); }
    /// The box of blocks with a non-zero majorant (block coordinates), empty if none.
    const openvdb::CoordBBox& bounds() const { return mBounds; }

private:
    openvdb::FloatTree mBlocks{0.0f};
    openvdb::CoordBBox mBounds;
};

/// The pieces of an index-space ray (unit direction, ray times in voxels) inside successive blocks
/// of the majorant grid, from ray time `t` until the ray leaves the grid's bounds.
class MajorantWalk {
public:
    MajorantWalk(const Majorants& majorants, Majorants::Accessor& acc, const Vec3d& eye,
                 const Vec3d& dir, double t);

    /// The next piece [t0, t1] and its majorant density; false past the last.
    bool next(double& t0, double& t1, float& majorant);

private:
    Majorants::Accessor& mAcc;
    Medium1D mBlockRay; ///< the ray in block coordinates, at the same ray times
    CellDda mDda;
    double mT = 0.0, mEnd = 0.0;
};

/// The density at index point ip (trilinear, BoxSampler's), through one thread's reader.
inline double densityAt(DensityReader& reader, const Vec3d& ip, bool levelSet)
{
    Cell c;
    c.origin = openvdb::Coord::floor(ip);
    double value;
    const Vec3d u = ip - Vec3d(c.origin.x(), c.origin.y(), c.origin.z());
    if (reader.cell(c.origin, c.v))
        value = c.at(u);
    else
        value = reader.tile;
    return levelSet ? (value < 0.0 ? 1.0 : 0.0) : std::max(0.0, value);
}

} // namespace volmorph::render
