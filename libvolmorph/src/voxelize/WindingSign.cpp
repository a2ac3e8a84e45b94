#include "voxelize/WindingSign.h"

#include "mesh/DisjointSets.h"
#include "mesh/WindingNumber.h"

#include <openvdb/math/Proximity.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <unordered_map>
#include <vector>
#include <cmath>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using openvdb::FloatTree;
using openvdb::Int32Grid;

/// OpenVDB's unsigned mode leaves some voxels near the band's edge up to 0.6 voxel too far (its
/// band expansion measures to a neighbour's triangle); the signed mode is exact. Each voxel here
/// takes the nearest of the closest triangles of its 27-neighbourhood, which restores the exact
/// distance (measured: worst 0.585 -> 0.14 voxel on a sphere at 128 across).
///
/// Only where needed: meshToVolume's first pass gives each triangle's exact distance to every
/// voxel within 0.866 voxel of it (its flood's test) and to their 26 neighbours. A voxel v at
/// distance d < 1.5 voxels from its closest triangle T, at q, has a voxel u within half a voxel of
/// q on each axis, which that flood reaches; each axis of v - u is an integer of at most d + 0.5
/// < 2, so v neighbours u and got |v - q| exactly. Values are never below the true distance, so a
/// value under 1.5 voxels is exact (measured: corrections start at 1.75).
void refineUnsignedDistance(FloatGrid& grid, const Int32Grid& index, const Mesh& mesh)
{
    const openvdb::math::Transform& xform = grid.transform();
    const float exact = 1.5f * float(xform.voxelSize()[0]);
    openvdb::tree::LeafManager<FloatTree> leaves(grid.tree());
    leaves.foreach ([&](FloatTree::LeafNodeType& leaf, size_t) {
        auto indices = index.getConstAccessor();
        int32_t candidates[27];
        for (auto it = leaf.beginValueOn(); it; ++it) {
            if (std::abs(*it) < exact) continue;
            const Coord ijk = it.getCoord();
            int count = 0;
            for (int dx = -1; dx <= 1; ++dx)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dz = -1; dz <= 1; ++dz) {
                        const int32_t t = indices.getValue(ijk.offsetBy(dx, dy, dz));
                        if (t < 0 || size_t(t) >= mesh.triangles.size()) continue;
                        if (std::find(candidates, candidates + count, t) == candidates + count)
                            candidates[count++] = t;
                    }
            const Vec3d p = xform.indexToWorld(ijk);
            double best = std::abs(*it);
            for (int c = 0; c < count; ++c) {
                const Vec3I& tri = mesh.triangles[size_t(candidates[c])];
                Vec3d uvw;
                const Vec3d q = openvdb::math::closestPointOnTriangleToPoint(
                    Vec3d(mesh.points[tri[0]]), Vec3d(mesh.points[tri[1]]),
                    Vec3d(mesh.points[tri[2]]), p, uvw);
                best = std::min(best, (q - p).length());
            }
            it.setValue(float(best));
        }
    });
}

namespace {

using Leaf = FloatTree::LeafNodeType;
constexpr openvdb::Index kLeafSize = Leaf::SIZE;

/// The active voxels of `leaf` joined to `seed` across faces whose two voxels lie d(u) + d(v) >
/// `voxel` from the surface (unsigned world distances): no surface passes between such voxels (a
/// crossing c on the segment would give d(u) + d(v) <= |uc| + |cv| = one voxel), so they share w's
/// side. `taken` marks the voxels already in a piece.
std::vector<openvdb::Index> pieceOf(const Leaf& leaf, openvdb::Index seed, float voxel,
                                    std::array<bool, kLeafSize>& taken)
{
    std::vector<openvdb::Index> members{seed};
    taken[seed] = true;
    for (size_t k = 0; k < members.size(); ++k) {
        const openvdb::Index u = members[k];
        const Coord c = Leaf::offsetToLocalCoord(u);
        for (int axis = 0; axis < 3; ++axis)
            for (const int step : {-1, 1}) {
                const int x = c[axis] + step;
                if (x < 0 || x >= int(Leaf::DIM)) continue;
                Coord n = c;
                n[axis] = x;
                const openvdb::Index v = Leaf::coordToOffset(n);
                if (taken[v] || !leaf.isValueOn(v)) continue;
                if (leaf.getValue(u) + leaf.getValue(v) <= voxel) continue;
                taken[v] = true;
                members.push_back(v);
            }
    }
    return members;
}

/// Signs the active voxels of one leaf of an unsigned band, evaluating w only where the sign can
/// change: once per piece (pieceOf) at its voxel farthest from the surface, checked at the piece's
/// voxel farthest from that one; where the two disagree (w crosses 1/2 away from the surface,
/// beside a hole that stayed open), at every voxel of the piece.
template <typename Inside>
void signLeaf(Leaf& leaf, float voxel, const Inside& inside)
{
    std::array<bool, kLeafSize> taken{};
    for (auto it = leaf.beginValueOn(); it; ++it) {
        if (taken[it.pos()]) continue;
        const std::vector<openvdb::Index> piece = pieceOf(leaf, it.pos(), voxel, taken);
        openvdb::Index deepest = piece[0];
        for (const openvdb::Index v : piece)
            if (leaf.getValue(v) > leaf.getValue(deepest)) deepest = v;
        const Coord a = Leaf::offsetToLocalCoord(deepest);
        openvdb::Index farthest = deepest;
        for (const openvdb::Index v : piece)
            if ((Leaf::offsetToLocalCoord(v) - a).asVec3i().lengthSqr() >
                (Leaf::offsetToLocalCoord(farthest) - a).asVec3i().lengthSqr())
                farthest = v;
        const Coord o = leaf.origin();
        const bool in = inside(o + a);
        const bool agree =
            farthest == deepest || inside(o + Leaf::offsetToLocalCoord(farthest)) == in;
        for (const openvdb::Index v : piece) {
            const bool vIn = agree ? in : inside(o + Leaf::offsetToLocalCoord(v));
            if (vIn) leaf.setValueOnly(v, -std::abs(leaf.getValue(v)));
        }
    }
}

/// The grid's tiles (inactive blocks outside the band), in the tree's iteration order.
std::vector<CoordBBox> tilesOf(const FloatTree& tree)
{
    std::vector<CoordBBox> boxes;
    for (auto it = tree.cbeginValueOff(); it; ++it)
        if (!it.isVoxelValue()) boxes.push_back(it.getBoundingBox());
    return boxes;
}

/// Tiles that touch across a face hold no surface between them (it lies in the band), so they
/// are on one side of it: the pieces of touching tiles, as each tile's representative. Each face
/// is probed once, beside its first corner: a small tile finds a large neighbour, not always the
/// reverse, which at worst splits a piece in two.
std::vector<uint32_t> tilePieces(const std::vector<CoordBBox>& boxes)
{
    // Each tile's number, stored as a tile of the same size and place.
    openvdb::Int32Tree numbers(-1);
    for (uint32_t i = 0; i < boxes.size(); ++i) {
        const int size = boxes[i].dim().x();
        using Lower = FloatTree::RootNodeType::ChildNodeType::ChildNodeType;
        const openvdb::Index level = size <= int(Leaf::DIM) ? 1 : size <= int(Lower::DIM) ? 2 : 3;
        numbers.addTile(level, boxes[i].min(), int32_t(i), true);
    }
    openvdb::tree::ValueAccessor<const openvdb::Int32Tree> number(numbers);
    DisjointSets sets(boxes.size());
    for (uint32_t i = 0; i < boxes.size(); ++i) {
        const CoordBBox& box = boxes[i];
        for (int axis = 0; axis < 3; ++axis)
            for (const int side : {-1, box.dim().x()}) {
                Coord p = box.min();
                p[axis] += side;
                const int32_t j = number.getValue(p);
                if (j >= 0) sets.unite(i, uint32_t(j));
            }
    }
    std::vector<uint32_t> piece(boxes.size());
    for (uint32_t i = 0; i < boxes.size(); ++i) piece[i] = sets.find(i);
    return piece;
}

/// Whether each tile is inside: w at the centres of a few tiles of each piece (tilePieces), one in
/// 64 and at least 3, spread through it; where they disagree (w crosses 1/2 away from the surface,
/// beside a hole that stayed open), w at every tile of the piece.
template <typename InsideAt>
std::vector<char> tileSides(const std::vector<CoordBBox>& boxes, const std::vector<uint32_t>& piece,
                            const InsideAt& insideAt)
{
    std::unordered_map<uint32_t, std::vector<uint32_t>> members;
    for (uint32_t i = 0; i < boxes.size(); ++i) members[piece[i]].push_back(i);
    std::vector<std::vector<uint32_t>> pieces;
    for (auto& [root, list] : members) pieces.push_back(std::move(list));
    std::vector<char> inside(boxes.size(), 0);
    tbb::parallel_for(size_t(0), pieces.size(), [&](size_t k) {
        const std::vector<uint32_t>& list = pieces[k];
        const size_t samples = std::min(list.size(), std::max<size_t>(3, list.size() / 64));
        const bool first = insideAt(boxes[list[0]]);
        bool agree = true;
        for (size_t s = 1; s < samples && agree; ++s)
            agree = insideAt(boxes[list[s * (list.size() - 1) / (samples - 1)]]) == first;
        if (agree)
            for (const uint32_t i : list) inside[i] = first;
        else
            tbb::parallel_for(size_t(0), list.size(),
                              [&](size_t j) { inside[list[j]] = insideAt(boxes[list[j]]); });
    });
    return inside;
}

} // namespace

/// Gives each active voxel of an unsigned band its sign from the winding number (signLeaf), then
/// fills the rest with OpenVDB's signedFloodFill and checks its work against the winding number:
/// every band leaf at its corners (a leaf whose check fails is evaluated voxel by voxel; this
/// happens beside holes, where flood fill has no surface to stop at), and the tiles by pieces
/// (tileSides).
void signByWindingNumber(FloatGrid& grid, const Mesh& mesh, Interrupter* interrupter)
{
    const detail::WindingNumber winding(mesh.points, mesh.triangles);
    const openvdb::math::Transform& xform = grid.transform();
    auto inside = [&](const Coord& ijk) { return winding(xform.indexToWorld(ijk)) > 0.5; };

    openvdb::tree::LeafManager<FloatTree> leaves(grid.tree());
    const float voxel = float(xform.voxelSize()[0]);
    leaves.foreach ([&](FloatTree::LeafNodeType& leaf, size_t) { signLeaf(leaf, voxel, inside); });
    throwIfInterrupted(interrupter, 70);

    openvdb::tools::signedFloodFill(grid.tree());
    throwIfInterrupted(interrupter, 75);

    const float background = grid.background();
    leaves.foreach ([&](FloatTree::LeafNodeType& leaf, size_t) {
        bool agrees = true;
        const Coord o = leaf.origin();
        for (int c = 0; c < 8 && agrees; ++c) {
            const Coord ijk = o.offsetBy((c & 1) ? 7 : 0, (c & 2) ? 7 : 0, (c & 4) ? 7 : 0);
            if (!leaf.isValueOn(ijk)) agrees = inside(ijk) == (leaf.getValue(ijk) < 0.0f);
        }
        if (agrees) return;
        for (auto it = leaf.beginValueOff(); it; ++it)
            it.setValue(inside(it.getCoord()) ? -background : background);
    });
    throwIfInterrupted(interrupter, 80);

    // Tiles: their pieces, each decided by a few of its tiles (tileSides).
    const std::vector<CoordBBox> boxes = tilesOf(grid.tree());
    const std::vector<char> tileInside =
        tileSides(boxes, tilePieces(boxes), [&](const CoordBBox& box) {
            const Vec3d centre = 0.5 * (box.min().asVec3d() + box.max().asVec3d());
            return winding(xform.indexToWorld(centre)) > 0.5;
        });
    size_t i = 0;
    for (auto it = grid.tree().beginValueOff(); it; ++it)
        if (!it.isVoxelValue()) it.setValue(tileInside[i++] ? -background : background);
    grid.setGridClass(openvdb::GRID_LEVEL_SET);
}

} // namespace volmorph::detail
