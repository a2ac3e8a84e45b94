// Mesh -> VolumeSet. See Voxelize.h for how inside and outside are decided.
//
// This is one of the few translation units that include OpenVDB's tools headers; keep it so.
#include <volmorph/Voxelize.h>

#include "mesh/Orientation.h"
#include "mesh/WindingNumber.h"

#include <openvdb/math/Proximity.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace volmorph {
namespace {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::FloatTree;
using openvdb::Int32Grid;
using openvdb::Vec3SGrid;

/// Bytes per voxel of the narrow band at the peak: sdf, polygon index, density and colour values
/// (4 + 4 + 4 + 12), meshToVolume's temporaries (about 16), doubled for partly filled leaves.
constexpr double kBytesPerBandVoxel = 80.0;

void checkInterrupt(Interrupter* interrupter, int percent)
{
    if (interrupter && interrupter->wasInterrupted(percent)) throw Interrupted();
}

std::string gib(uint64_t bytes)
{
    std::ostringstream s;
    s.precision(3);
    s << double(bytes) / double(1ull << 30) << " GiB";
    return s.str();
}

/// OpenVDB's unsigned mode leaves some voxels near the band's edge up to 0.6 voxel too far (its
/// band expansion measures to a neighbour's triangle); the signed mode is exact. Each voxel here
/// takes the nearest of the closest triangles of its 27-neighbourhood, which restores the exact
/// distance (measured: worst 0.585 -> 0.14 voxel on a sphere at 128 across).
void refineUnsignedDistance(FloatGrid& grid, const Int32Grid& index, const Mesh& mesh)
{
    const openvdb::math::Transform& xform = grid.transform();
    openvdb::tree::LeafManager<FloatTree> leaves(grid.tree());
    leaves.foreach ([&](FloatTree::LeafNodeType& leaf, size_t) {
        auto indices = index.getConstAccessor();
        int32_t candidates[27];
        for (auto it = leaf.beginValueOn(); it; ++it) {
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

/// Gives each active voxel of an unsigned band its sign from the winding number, then fills the
/// rest with OpenVDB's signedFloodFill and checks its work against the winding number: every tile
/// at its centre, and every band leaf at its corners (a leaf whose check fails is evaluated voxel
/// by voxel; this happens beside holes, where flood fill has no surface to stop at).
void signByWindingNumber(FloatGrid& grid, const Mesh& mesh, Interrupter* interrupter)
{
    const detail::WindingNumber winding(mesh.points, mesh.triangles);
    const openvdb::math::Transform& xform = grid.transform();
    auto inside = [&](const Coord& ijk) { return winding(xform.indexToWorld(ijk)) > 0.5; };

    openvdb::tree::LeafManager<FloatTree> leaves(grid.tree());
    leaves.foreach ([&](FloatTree::LeafNodeType& leaf, size_t) {
        for (auto it = leaf.beginValueOn(); it; ++it)
            if (inside(it.getCoord())) it.setValue(-std::abs(*it));
    });
    checkInterrupt(interrupter, 70);

    openvdb::tools::signedFloodFill(grid.tree());
    checkInterrupt(interrupter, 75);

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
    checkInterrupt(interrupter, 80);

    // A tile holds no band voxel, so no surface passes through it: one query at its centre decides
    // it.
    for (auto it = grid.tree().beginValueOff(); it; ++it) {
        if (it.isVoxelValue()) continue;
        const openvdb::CoordBBox box = it.getBoundingBox();
        const Vec3d centre = xform.indexToWorld(0.5 * (box.min().asVec3d() + box.max().asVec3d()));
        it.setValue(winding(centre) > 0.5 ? -background : background);
    }
    grid.setGridClass(openvdb::GRID_LEVEL_SET);
}

/// Colour on the band: vertex colours interpolated at the closest point of the closest triangle.
Vec3SGrid::Ptr colorFromIndex(const Mesh& mesh, const Int32Grid* index, const FloatGrid& sdf,
                              const std::optional<Vec3f>& constant)
{
    Vec3f mean(0.8f); // grey, when neither the scene nor the file gives a colour
    if (constant)
        mean = *constant;
    else if (mesh.hasColors()) {
        Vec3d sum(0.0);
        for (const Vec3f& c : mesh.colors) sum += Vec3d(c);
        mean = Vec3f(sum / double(mesh.colors.size()));
    }
    auto color = Vec3SGrid::create(mean);
    color->setTransform(sdf.transform().copy());
    color->setName(kColorGridName);
    color->setGridClass(openvdb::GRID_UNKNOWN);
    color->setVectorType(openvdb::VEC_INVARIANT);
    const bool interpolate = !constant && mesh.hasColors() && index;
    if (!interpolate) {
        // One colour everywhere: active tiles over the band's blocks, no voxels (a 1000-across
        // sphere's band would hold 0.4 GB of equal colours as leaves).
        for (auto leaf = sdf.tree().cbeginLeaf(); leaf; ++leaf)
            color->tree().addTile(1, leaf->origin(), mean, true);
        return color;
    }
    color->tree().topologyUnion(sdf.tree());
    using ColorTree = Vec3SGrid::TreeType;
    openvdb::tree::LeafManager<ColorTree> leaves(color->tree());
    const openvdb::math::Transform& xform = sdf.transform();
    leaves.foreach ([&](ColorTree::LeafNodeType& leaf, size_t) {
        const auto* indexLeaf = index->tree().probeConstLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            Vec3f c = mean;
            if (indexLeaf) {
                const int32_t t = indexLeaf->getValue(it.pos());
                if (t >= 0 && size_t(t) < mesh.triangles.size()) {
                    const Vec3I& tri = mesh.triangles[size_t(t)];
                    Vec3d uvw;
                    openvdb::math::closestPointOnTriangleToPoint(
                        Vec3d(mesh.points[tri[0]]), Vec3d(mesh.points[tri[1]]),
                        Vec3d(mesh.points[tri[2]]), xform.indexToWorld(it.getCoord()), uvw);
                    c = Vec3f(uvw[0] * Vec3d(mesh.colors[tri[0]]) +
                              uvw[1] * Vec3d(mesh.colors[tri[1]]) +
                              uvw[2] * Vec3d(mesh.colors[tri[2]]));
                }
            }
            it.setValue(c);
        }
    });
    return color;
}

/// The estimated bytes of voxelizing `input`; a UserError when they pass the memory limit or the
/// index coordinates (32-bit) come near their limit.
uint64_t checkBudget(const Mesh& input, const VoxelizeOptions& options, double voxelSize,
                     float halfWidth, const SourceLocation& where)
{
    const auto [lo, hi] = input.bounds();
    const Vec3d extent = hi - lo;
    const double cells = std::max({extent.x(), extent.y(), extent.z()}) / voxelSize;
    const uint64_t limit =
        options.memoryLimitBytes ? options.memoryLimitBytes : defaultMemoryLimitBytes();
    const uint64_t estimate = estimateVoxelizeBytes(input, voxelSize, halfWidth);
    if (cells > 1e6 || estimate > limit) {
        std::ostringstream s;
        s << "voxel size " << voxelSize << " world units gives " << std::ceil(cells)
          << " voxels across the mesh and needs about " << gib(estimate)
          << ", more than the limit of " << gib(limit)
          << "; use a larger voxel size (or fewer voxels across), or raise the limit "
          << "with --memory-limit (default: half the machine's memory)";
        throw UserError(where, s.str());
    }
    return estimate;
}

/// The sign from the winding number (else OpenVDB's flood fill): asked for, or, by default, for
/// every mesh but a closed single shell.
bool usesWindingNumber(const Mesh& input, const VoxelizeOptions& options)
{
    switch (options.sign) {
    case VoxelizeOptions::Sign::FloodFill:
        return false;
    case VoxelizeOptions::Sign::WindingNumber:
        return true;
    case VoxelizeOptions::Sign::Auto:
        break;
    }
    return !(input.report.watertight() && input.report.components == 1);
}

} // namespace

/// density = smoothstep of the signed distance across [-ramp, +ramp] (0.5 on the surface), 1 in
/// the interior as active tiles, 0 outside and inactive.
FloatGrid::Ptr fogFromLevelSet(const FloatGrid& sdf, float rampWorld)
{
    FloatGrid::Ptr density = sdf.deepCopy();
    FloatTree& tree = density->tree();
    openvdb::tree::LeafManager<FloatTree> leaves(tree);
    leaves.foreach ([&](FloatTree::LeafNodeType& leaf, size_t) {
        for (auto it = leaf.beginValueAll(); it; ++it) {
            const float d = *it;
            const float value = fogOfLevelSet(d, it.isValueOn(), rampWorld);
            it.setValue(value);
            it.setValueOn(value > 0.0f);
        }
    });
    auto tiles = tree.beginValueAll();
    tiles.setMaxDepth(tiles.getLeafDepth() - 1); // tiles only, not every voxel
    for (auto it = tiles; it; ++it) {
        const bool inside = *it < 0.0f;
        it.setValue(inside ? 1.0f : 0.0f);
        it.setActiveState(inside);
    }
    tree.root().setBackground(0.0f, /*updateChildNodes=*/true);
    openvdb::tools::prune(tree);
    density->setGridClass(openvdb::GRID_FOG_VOLUME);
    density->setName(kDensityGridName);
    return density;
}

double resolveVoxelSize(const Mesh& mesh, const VoxelizeOptions& options)
{
    if (options.voxelSize) return *options.voxelSize;
    const auto [lo, hi] = mesh.bounds();
    const Vec3d extent = hi - lo;
    const double longest = std::max({extent.x(), extent.y(), extent.z()});
    return longest / double(std::max(1, options.resolution));
}

uint64_t estimateVoxelizeBytes(const Mesh& mesh, double voxelSize, float halfWidthVoxels)
{
    double area = 0.0;
    for (const Vec3I& t : mesh.triangles) {
        const Vec3d a(mesh.points[t[0]]), b(mesh.points[t[1]]), c(mesh.points[t[2]]);
        area += 0.5 * (b - a).cross(c - a).length();
    }
    const double bandVoxels = area / (voxelSize * voxelSize) * 2.0 * double(halfWidthVoxels);
    const double bytes = bandVoxels * kBytesPerBandVoxel + double(64ull << 20);
    return bytes > 1.8e19 ? UINT64_MAX : uint64_t(bytes);
}

VolumeSet voxelize(const Mesh& input, const VoxelizeOptions& options, Interrupter* interrupter,
                   VoxelizeStats* stats)
{
    const SourceLocation where{input.file.string()};
    if (input.triangles.empty()) throw UserError(where, "the mesh has no triangles to voxelize");
    const double voxelSize = resolveVoxelSize(input, options);
    if (!(voxelSize > 0.0) || !std::isfinite(voxelSize))
        throw UserError(where, "the voxel size must be a positive number of world units (the mesh "
                               "may be flat or a single point)");
    const float halfWidth = std::max(3.0f, options.halfWidthVoxels);

    const uint64_t estimate = checkBudget(input, options, voxelSize, halfWidth, where);

    if (interrupter) interrupter->start("voxelize");
    const bool useWinding = usesWindingNumber(input, options);
    Mesh repaired;
    if (useWinding) {
        repaired = input;
        detail::repairOrientation(repaired);
    }
    const Mesh& mesh = useWinding ? repaired : input;

    const openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(voxelSize);
    std::vector<Vec3f> indexPoints(mesh.points.size());
    for (size_t i = 0; i < mesh.points.size(); ++i)
        indexPoints[i] = Vec3f(xform->worldToIndex(Vec3d(mesh.points[i])));
    const openvdb::tools::QuadAndTriangleDataAdapter<Vec3f, Vec3I> adapter(indexPoints,
                                                                           mesh.triangles);

    // The winding-number path refines OpenVDB's unsigned distances with the closest triangles.
    const bool needIndex = useWinding || (!options.color && mesh.hasColors());
    Int32Grid::Ptr index = needIndex ? Int32Grid::create(-1) : nullptr;
    openvdb::util::NullInterrupter none;
    openvdb::util::NullInterrupter& hook = interrupter ? *interrupter : none;
    const int flags = useWinding ? openvdb::tools::UNSIGNED_DISTANCE_FIELD : 0;
    FloatGrid::Ptr sdf = openvdb::tools::meshToVolume<FloatGrid>(hook, adapter, *xform, halfWidth,
                                                                 halfWidth, flags, index.get());
    checkInterrupt(interrupter, 60);
    if (useWinding) {
        refineUnsignedDistance(*sdf, *index, mesh);
        signByWindingNumber(*sdf, mesh, interrupter);
    }
    sdf->setName(kSdfGridName);
    sdf->setGridClass(openvdb::GRID_LEVEL_SET);

    VolumeSet out;
    out.sdf = sdf;
    out.density = fogFromLevelSet(*sdf, options.densityRampVoxels * float(voxelSize));
    checkInterrupt(interrupter, 90);
    out.color = colorFromIndex(mesh, index.get(), *sdf, options.color);
    checkInterrupt(interrupter, 100);
    if (interrupter) interrupter->end();

    if (stats) {
        stats->voxelSize = voxelSize;
        stats->usedWindingNumber = useWinding;
        stats->estimatedBytes = estimate;
        stats->sdfActiveVoxels = out.sdf->activeVoxelCount();
        stats->densityActiveVoxels = out.density->activeVoxelCount();
    }
    return out;
}

} // namespace volmorph
