// Mesh -> VolumeSet: signed distance, fog density and colour grids on one transform.
//
// How inside and outside are decided:
// - A watertight mesh of one shell takes OpenVDB's fast path: tools::meshToVolume computes the
//   signed narrow band and fills the interior by its scanline sweep and flood fill, which is
//   exact for such meshes whatever their orientation.
// - Every other mesh (holes, non-manifold edges, several or nested shells) gets an unsigned narrow
//   band from tools::meshToVolume and its sign from the generalized winding number w(p) (Jacobson
//   et al. 2013), evaluated fast with a bounding-volume hierarchy and the far-field dipole
//   approximation of Barill et al. 2018: p is inside when w(p) > 0.5. Before that, each shell's
//   triangles are made consistently oriented (the majority orientation of the shell wins), and a
//   shell with negative volume that lies inside no other shell is turned outward (an inverted
//   file); a shell inside another keeps the file's orientation, so an inward-facing inner shell is
//   a cavity and an outward-facing one is solid. Holes lower w smoothly instead of flipping it,
//   so a mesh missing a fifth of its triangles still has a solid interior. Regions away from the
//   band take their sign from OpenVDB's signedFloodFill, and every tile it produced is checked
//   against w at the tile's centre.
// - Colour: each band voxel's closest triangle comes from meshToVolume's polygon index grid (the
//   exact closest triangle, computed in the same pass); the vertex colours are interpolated
//   barycentrically at the closest point on it.
#pragma once

#include <algorithm>

#include <volmorph/core/Interrupter.h>
#include <volmorph/core/MemoryLimit.h>
#include <volmorph/Mesh.h>
#include <volmorph/VolumeSet.h>

#include <cstdint>
#include <optional>

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
    /// Refuse to start when the estimate exceeds this many bytes; 0 = half the machine's RAM.
    uint64_t memoryLimitBytes = 0;
    enum class Sign { Auto, FloodFill, WindingNumber };
    /// Auto: flood fill for watertight single-shell meshes, winding number otherwise.
    Sign sign = Sign::Auto;
};

/// What voxelize() did, for logs and tests.
struct VoxelizeStats {
    double voxelSize = 0.0; ///< world units
    bool usedWindingNumber = false;
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
