// Mesh -> VolumeSet. See Voxelize.h for how inside and outside are decided. OpenVDB's
// meshToVolume is instantiated once, in voxelize/MeshBand.cpp.
#include <volmorph/Voxelize.h>

#include "mesh/HoleFill.h"
#include "mesh/Orientation.h"
#include "voxelize/MeshBand.h"
#include "voxelize/WindingSign.h"

#include <openvdb/math/Proximity.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace volmorph {
namespace {

using openvdb::FloatGrid;
using openvdb::FloatTree;
using openvdb::Int32Grid;
using openvdb::Vec3SGrid;

/// Bytes per voxel of the narrow band at the peak: sdf, polygon index, density and colour values
/// (4 + 4 + 4 + 12), meshToVolume's temporaries (about 16), doubled for partly filled leaves.
constexpr double kBytesPerBandVoxel = 80.0;

std::string gib(uint64_t bytes)
{
    std::ostringstream s;
    s.precision(3);
    s << double(bytes) / double(1ull << 30) << " GiB";
    return s.str();
}

/// A vertex attribute on the band: `values` (one per vertex of `mesh`, or fewer: the rest are 0)
/// interpolated at each voxel's closest point on its closest triangle; `mean` where there is none.
void attributeFromIndex(const Mesh& mesh, const std::vector<Vec3f>& values, const Int32Grid& index,
                        const FloatGrid& sdf, Vec3SGrid& grid)
{
    grid.tree().topologyUnion(sdf.tree());
    using AttributeTree = Vec3SGrid::TreeType;
    openvdb::tree::LeafManager<AttributeTree> leaves(grid.tree());
    const openvdb::math::Transform& xform = sdf.transform();
    const Vec3f mean = grid.background();
    auto value = [&](uint32_t v) { return v < values.size() ? Vec3d(values[v]) : Vec3d(0.0); };
    leaves.foreach ([&](AttributeTree::LeafNodeType& leaf, size_t) {
        const auto* indexLeaf = index.tree().probeConstLeaf(leaf.origin());
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
                    c = Vec3f(uvw[0] * value(tri[0]) + uvw[1] * value(tri[1]) +
                              uvw[2] * value(tri[2]));
                }
            }
            it.setValue(c);
        }
    });
}

Vec3SGrid::Ptr bandGrid(const FloatGrid& sdf, const Vec3f& background, const char* name,
                        openvdb::VecType type)
{
    auto grid = Vec3SGrid::create(background);
    grid->setTransform(sdf.transform().copy());
    grid->setName(name);
    grid->setGridClass(openvdb::GRID_UNKNOWN);
    grid->setVectorType(type);
    return grid;
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
    auto color = bandGrid(sdf, mean, kColorGridName, openvdb::VEC_INVARIANT);
    const bool interpolate = !constant && mesh.hasColors() && index;
    if (!interpolate) {
        // One colour everywhere: active tiles over the band's blocks, no voxels (a 1000-across
        // sphere's band would hold 0.4 GB of equal colours as leaves).
        for (auto leaf = sdf.tree().cbeginLeaf(); leaf; ++leaf)
            color->tree().addTile(1, leaf->origin(), mean, true);
        return color;
    }
    attributeFromIndex(mesh, mesh.colors, *index, sdf, *color);
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
          << "; use a larger voxel size (or fewer voxels across), or raise the memory limit";
        throw MemoryLimitExceeded(where, s.str(), estimate, limit);
    }
    return estimate;
}

/// How `input` gets its sign (Voxelize.h): `prepared` is what is voxelized, the input itself or,
/// unless it is a closed single shell, a copy with its orientation repaired and its holes filled.
VoxelizeStats::SignPath prepareMesh(const Mesh& input, const VoxelizeOptions& options,
                                    double voxelSize, Mesh& prepared, size_t& holesFilled)
{
    using Path = VoxelizeStats::SignPath;
    const bool closedShell = input.report.watertight() && input.report.components == 1;
    if (options.sign == VoxelizeOptions::Sign::FloodFill ||
        (options.sign == VoxelizeOptions::Sign::Auto && closedShell))
        return Path::FloodFill;
    prepared = input;
    detail::repairOrientation(prepared);
    if (prepared.report.boundaryEdges > 0)
        holesFilled = detail::fillHoles(prepared, voxelSize).holes;
    if (options.sign == VoxelizeOptions::Sign::Auto && prepared.report.watertight())
        return Path::ClosedShells;
    return Path::WindingNumber;
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
    Mesh prepared;
    size_t holesFilled = 0;
    const VoxelizeStats::SignPath path =
        prepareMesh(input, options, voxelSize, prepared, holesFilled);
    const Mesh& mesh = path == VoxelizeStats::SignPath::FloodFill ? input : prepared;

    const openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(voxelSize);
    std::vector<Vec3f> indexPoints(mesh.points.size());
    for (size_t i = 0; i < mesh.points.size(); ++i)
        indexPoints[i] = Vec3f(xform->worldToIndex(Vec3d(mesh.points[i])));

    // The winding-number path refines OpenVDB's unsigned distances with the closest triangles.
    const bool winding = path == VoxelizeStats::SignPath::WindingNumber;
    const bool needIndex =
        winding || (!options.color && mesh.hasColors()) || !options.vertexVelocity.empty();
    Int32Grid::Ptr index = needIndex ? Int32Grid::create(-1) : nullptr;
    openvdb::util::NullInterrupter none;
    openvdb::util::NullInterrupter& hook = interrupter ? *interrupter : none;
    FloatGrid::Ptr sdf =
        path == VoxelizeStats::SignPath::ClosedShells
            ? detail::closedShellsLevelSet(mesh, indexPoints, *xform, halfWidth, index.get(), hook)
            : detail::meshBand(indexPoints, mesh.triangles, *xform, halfWidth, winding, index.get(),
                               hook);
    throwIfInterrupted(interrupter, 60);
    if (winding) {
        detail::refineUnsignedDistance(*sdf, *index, mesh);
        detail::signByWindingNumber(*sdf, mesh, interrupter);
    }
    sdf->setName(kSdfGridName);
    sdf->setGridClass(openvdb::GRID_LEVEL_SET);

    VolumeSet out;
    out.sdf = sdf;
    out.density = fogFromLevelSet(*sdf, options.densityRampVoxels * float(voxelSize));
    throwIfInterrupted(interrupter, 90);
    out.color = colorFromIndex(mesh, index.get(), *sdf, options.color);
    if (!options.vertexVelocity.empty()) {
        out.velocity =
            bandGrid(*sdf, Vec3f(0.0f), kVelocityGridName, openvdb::VEC_CONTRAVARIANT_RELATIVE);
        attributeFromIndex(mesh, options.vertexVelocity, *index, *sdf, *out.velocity);
    }
    throwIfInterrupted(interrupter, 100);
    if (interrupter) interrupter->end();

    if (stats) {
        stats->voxelSize = voxelSize;
        stats->signPath = path;
        stats->holesFilled = holesFilled;
        stats->estimatedBytes = estimate;
        stats->sdfActiveVoxels = out.sdf->activeVoxelCount();
        stats->densityActiveVoxels = out.density->activeVoxelCount();
    }
    return out;
}

} // namespace volmorph
