// Mesh -> VolumeSet: signed distance, fog density and colour grids on one transform.
//
// How inside and outside are decided:
// - A watertight mesh of one shell takes OpenVDB's fast path: tools::meshToVolume computes the
//   signed narrow band and fills the interior by its scanline sweep and flood fill, which is
//   exact for such meshes whatever their orientation.
// - Every other mesh is inside where its generalized winding number w(p) (Jacobson et al. 2013)
//   exceeds 1/2, after two repairs:
//   - Orientation: each shell's triangles are made consistently oriented (the majority of the
//     shell wins), and a shell of negative volume that lies inside no other shell is turned
//     outward (an inverted file); a shell inside another keeps the file's orientation, so an
//     inward-facing inner shell is a cavity and an outward-facing one is solid.
//   - Holes: every boundary loop is closed by a patch that continues the surface around it
//     (mesh/HoleFill.h: a disc whose vertices minimize the thin-plate energy, the squared umbrella
//     Laplacians of the patch and its rim, so tangent planes match across the rim). Left to
//     itself, w falls toward 1/2 near a large hole (on the disc spanning a sphere's missing cap
//     it is exactly 1/2), and a slab of the object would be lost; with the patch, a sphere without
//     an eighth of its area keeps 99.8% of its interior (IoU), not 95.6%.
//   Then, when every shell is closed (the usual case after filling), w is the count of shells
//   that enclose p, +1 for each facing outward and -1 for each facing inward: each shell goes
//   through OpenVDB's signed path and a band voxel counts the shells it is inside
//   (voxelize/MeshBand.h), with exact distances and no w evaluated anywhere. A single shell is
//   OpenVDB's own result. Only a mesh still open after filling (a boundary that does not close
//   into a loop, non-manifold edges) evaluates w itself (a bounding-volume hierarchy and the dipole
//   approximation of Barill et al. 2018), over an unsigned band and only where the sign can
//   change: once per piece of a band leaf with no surface between its voxels, and at a few tiles
//   of each piece of touching tiles, more where those disagree (voxelize/WindingSign.h).
// - What this rule does not handle: a hole is closed by the smoothest continuation of the
//   surface around it, which is not what a user meant when the missing part was not smooth (a
//   unit cube without its top face gets a pyramid 0.26 high as its lid, not a flat one: the
//   patch is no finer than the mesh around the hole, here one vertex) or was meant to stay open:
//   a cup without its base is closed, and an open sheet (a single surface with no inside, such as
//   a terrain patch) becomes a thin solid between the sheet and its patch. Patches are not tested
//   against the mesh, so a hole whose rim folds over itself can give a patch that pierces the
//   surface; OpenVDB's flood fill then keeps every region the shell encloses.
// - Colour: each band voxel's closest triangle comes from meshToVolume's polygon index grid (the
//   exact closest triangle, computed in the same pass); the vertex colours are interpolated
//   barycentrically at the closest point on it. A patch's vertices take colours faired like their
//   positions.
#pragma once

#include <algorithm>

#include <volmorph/core/Interrupter.h>
#include <volmorph/core/MemoryLimit.h>
#include <volmorph/Mesh.h>
#include <volmorph/VolumeSet.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace volmorph {

struct VoxelizeOptions {
    /// Voxel edge in world units. When unset, `resolution` voxels span the longest side of the
    /// mesh's bounds.
    std::optional<double> voxelSize;
    int resolution = 128;
    /// Narrow band half width in voxels on each side of the surface (at least 3).
    float halfWidthVoxels = 3.0f;
    /// Half the width of the density ramp across the surface, in voxels.
    float densityRampVoxels = 1.5f;
    /// A constant colour instead of the mesh's vertex colours.
    std::optional<Vec3f> color;
    /// Per vertex of the mesh, world units per second: when given, VolumeSet::velocity holds it
    /// on the sdf's band, interpolated at each voxel's closest surface point as the colours are
    /// (a hole's patch vertices move with nothing: zero). Empty: no velocity grid.
    std::vector<Vec3f> vertexVelocity;
    /// Refuse to start when the estimate exceeds this many bytes; 0 = half the machine's RAM.
    uint64_t memoryLimitBytes = 0;
    enum class Sign { Auto, FloodFill, WindingNumber };
    /// Auto: as described at the top of this file. FloodFill: OpenVDB's flood fill of the mesh as
    /// it is. WindingNumber: repairs, then w evaluated over the band whatever the shells.
    Sign sign = Sign::Auto;
};

/// What voxelize() did, for logs and tests.
struct VoxelizeStats {
    double voxelSize = 0.0; ///< world units
    /// How the inside was decided (see the top of this file): OpenVDB's flood fill of the input,
    /// the count of closed shells (after repairs), or the winding number evaluated.
    enum class SignPath { FloodFill, ClosedShells, WindingNumber };
    SignPath signPath = SignPath::FloodFill;
    size_t holesFilled = 0; ///< boundary loops closed by patches
    uint64_t estimatedBytes = 0;
    uint64_t sdfActiveVoxels = 0;
    uint64_t densityActiveVoxels = 0; ///< including voxels of active tiles
};

/// The fog of a signed distance d (world units): smoothstep of -d across [-ramp, +ramp], 0.5 on
/// the surface.
inline float fogRamp(float d, float rampWorld)
{
    const float x = std::clamp(0.5f - d / (2.0f * rampWorld), 0.0f, 1.0f);
    return x * x * (3.0f - 2.0f * x);
}

/// The fog of one level-set value d (world units): fogRamp on the band (`active`), 1 inside it, 0
/// outside.
inline float fogOfLevelSet(float d, bool active, float rampWorld)
{
    return active ? fogRamp(d, rampWorld) : (d < 0.0f ? 1.0f : 0.0f);
}

/// A fog from a level set (world units): fogOfLevelSet of every value, the interior as active
/// tiles of 1.
openvdb::FloatGrid::Ptr fogFromLevelSet(const openvdb::FloatGrid& sdf, float rampWorld);

/// The voxel size the options give for `mesh` (world units).
double resolveVoxelSize(const Mesh& mesh, const VoxelizeOptions& options);

/// An estimate of voxelize()'s peak memory in bytes, from the surface area and the band.
uint64_t estimateVoxelizeBytes(const Mesh& mesh, double voxelSize, float halfWidthVoxels);

/// Voxelizes `mesh` (world units). Throws UserError when the mesh is empty or the estimate
/// exceeds the memory limit, Interrupted when `interrupter` asks to stop.
VolumeSet voxelize(const Mesh& mesh, const VoxelizeOptions& options,
                   Interrupter* interrupter = nullptr, VoxelizeStats* stats = nullptr);

} // namespace volmorph
