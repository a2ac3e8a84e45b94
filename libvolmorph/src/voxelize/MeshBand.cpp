#include "voxelize/MeshBand.h"

#include "mesh/DisjointSets.h"

#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>

#include <array>
#include <cmath>
#include <limits>

namespace volmorph::detail {
namespace {

using openvdb::CoordBBox;
using openvdb::FloatGrid;
using openvdb::FloatTree;
using openvdb::Int32Grid;

/// A connected shell: its triangles, and for each the index of the same triangle in the mesh.
struct Shell {
    std::vector<Vec3I> triangles;
    std::vector<int32_t> meshTriangle;
    int orientation = 1; ///< +1 facing outward (positive volume), -1 facing inward
};

/// The mesh's shells (connected by shared vertices), in the order of their first triangles.
std::vector<Shell> shellsOf(const Mesh& mesh)
{
    DisjointSets sets(mesh.points.size());
    for (const Vec3I& t : mesh.triangles) {
        sets.unite(t[0], t[1]);
        sets.unite(t[1], t[2]);
    }
    std::vector<int32_t> shellOfRoot(mesh.points.size(), -1);
    std::vector<Shell> shells;
    std::vector<double> volume;
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        const Vec3I& t = mesh.triangles[i];
        int32_t& s = shellOfRoot[sets.find(t[0])];
        if (s < 0) {
            s = int32_t(shells.size());
            shells.emplace_back();
            volume.push_back(0.0);
        }
        shells[size_t(s)].triangles.push_back(t);
        shells[size_t(s)].meshTriangle.push_back(int32_t(i));
        volume[size_t(s)] +=
            Vec3d(mesh.points[t[0]]).dot(Vec3d(mesh.points[t[1]]).cross(Vec3d(mesh.points[t[2]])));
    }
    for (size_t s = 0; s < shells.size(); ++s) shells[s].orientation = volume[s] < 0.0 ? -1 : 1;
    return shells;
}

/// One shell's signed band, with its closest-triangle grid when `withIndex`.
struct ShellBand {
    FloatGrid::Ptr sdf;
    Int32Grid::Ptr index;
    CoordBBox box; ///< the band's active voxels: the shell and everything it encloses lie inside
};

/// A shell's value at the voxels of one block: its leaf there, or the tile that covers the block.
struct ShellBlock {
    const FloatTree::LeafNodeType* leaf = nullptr;
    float tile = 0.0f;
    float value(openvdb::Index i) const { return leaf ? leaf->getValue(i) : tile; }
    bool inBand(openvdb::Index i) const { return leaf && leaf->isValueOn(i); }
};

/// Gives each active voxel of `leaf` its distance (the smallest |d| over the shells whose band
/// holds it) and sign (inside when the shells that enclose it count at least 1), and its closest
/// triangle when `index` is given.
void combineLeaf(FloatTree::LeafNodeType& leaf, const std::vector<Shell>& shells,
                 const std::vector<ShellBand>& bands, Int32Grid* index)
{
    constexpr openvdb::Index kSize = FloatTree::LeafNodeType::SIZE;
    std::array<float, kSize> best;
    std::array<int32_t, kSize> triangle, count; // the closest triangle (in the mesh), -1: none
    best.fill(std::numeric_limits<float>::max());
    triangle.fill(-1);
    count.fill(0);
    const CoordBBox box = leaf.getNodeBoundingBox();
    for (size_t s = 0; s < bands.size(); ++s) {
        if (!bands[s].box.hasOverlap(box)) continue;
        ShellBlock block;
        block.leaf = bands[s].sdf->tree().probeConstLeaf(leaf.origin());
        if (!block.leaf) block.tile = bands[s].sdf->tree().getValue(leaf.origin());
        const auto* indexLeaf =
            index && block.leaf ? bands[s].index->tree().probeConstLeaf(leaf.origin()) : nullptr;
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const openvdb::Index i = it.pos();
            const float d = block.value(i);
            if (d < 0.0f) count[i] += shells[s].orientation;
            if (block.inBand(i) && std::abs(d) < best[i]) {
                best[i] = std::abs(d);
                const int32_t local = indexLeaf ? indexLeaf->getValue(i) : -1;
                triangle[i] = local < 0 ? -1 : shells[s].meshTriangle[size_t(local)];
            }
        }
    }
    auto* indexLeaf = index ? index->tree().probeLeaf(leaf.origin()) : nullptr;
    for (auto it = leaf.beginValueOn(); it; ++it) {
        const openvdb::Index i = it.pos();
        it.setValue(count[i] >= 1 ? -best[i] : best[i]);
        if (indexLeaf) indexLeaf->setValueOn(i, triangle[i]);
    }
}

} // namespace

FloatGrid::Ptr meshBand(const std::vector<Vec3f>& indexPoints, const std::vector<Vec3I>& triangles,
                        const openvdb::math::Transform& xform, float halfWidth,
                        bool unsignedDistance, Int32Grid* index,
                        openvdb::util::NullInterrupter& interrupter)
{
    const openvdb::tools::QuadAndTriangleDataAdapter<Vec3f, Vec3I> adapter(indexPoints, triangles);
    const int flags = unsignedDistance ? openvdb::tools::UNSIGNED_DISTANCE_FIELD : 0;
    return openvdb::tools::meshToVolume<FloatGrid>(interrupter, adapter, xform, halfWidth,
                                                   halfWidth, flags, index);
}

FloatGrid::Ptr closedShellsLevelSet(const Mesh& mesh, const std::vector<Vec3f>& indexPoints,
                                    const openvdb::math::Transform& xform, float halfWidth,
                                    Int32Grid* index, openvdb::util::NullInterrupter& interrupter)
{
    const std::vector<Shell> shells = shellsOf(mesh);
    if (shells.size() <= 1)
        return meshBand(indexPoints, mesh.triangles, xform, halfWidth, false, index, interrupter);

    std::vector<ShellBand> bands(shells.size());
    const float background = halfWidth * float(xform.voxelSize()[0]);
    FloatGrid::Ptr sdf = FloatGrid::create(background);
    sdf->setTransform(xform.copy());
    for (size_t s = 0; s < shells.size(); ++s) {
        if (index) bands[s].index = Int32Grid::create(-1);
        bands[s].sdf = meshBand(indexPoints, shells[s].triangles, xform, halfWidth, false,
                                bands[s].index.get(), interrupter);
        if (interrupter.wasInterrupted()) return sdf;
        bands[s].box = bands[s].sdf->evalActiveVoxelBoundingBox();
        sdf->tree().topologyUnion(bands[s].sdf->tree());
    }
    if (index) index->tree().topologyUnion(sdf->tree());
    openvdb::tree::LeafManager<FloatTree> leaves(sdf->tree());
    leaves.foreach (
        [&](FloatTree::LeafNodeType& leaf, size_t) { combineLeaf(leaf, shells, bands, index); });
    openvdb::tools::signedFloodFill(sdf->tree());
    sdf->setGridClass(openvdb::GRID_LEVEL_SET);
    return sdf;
}

} // namespace volmorph::detail
