// The voxel representation of one object (or one in-between): its grids on one transform.
#pragma once

#include <openvdb/openvdb.h>

#include <filesystem>
#include <map>
#include <string>

namespace volmorph {

/// Grid names, as written to .vdb files.
inline constexpr const char* kSdfGridName = "sdf";
inline constexpr const char* kDensityGridName = "density";
inline constexpr const char* kColorGridName = "Cd";
inline constexpr const char* kVelocityGridName = "vel";

struct VolumeSet {
    /// Signed distance in world units, negative inside; GRID_LEVEL_SET with a narrow band of
    /// halfWidth voxels on each side, +/- background beyond it.
    openvdb::FloatGrid::Ptr sdf;
    /// Fog density: 1 inside, a smooth ramp across the surface (0.5 on it), 0 outside. The interior
    /// is stored as active tiles of 1; GRID_FOG_VOLUME.
    openvdb::FloatGrid::Ptr density;
    /// Linear RGB colour, active on the sdf's narrow band; the background is the mean colour.
    openvdb::Vec3SGrid::Ptr color;
    /// Every other grid a volume input carries (temperature, flame, ...): float or vec3 grids by
    /// name, warped like Cd and blended with their own schedules (blend.grids).
    std::map<std::string, openvdb::GridBase::Ptr> extras;
    /// An in-between's velocity, world units per second: the motion of the material it shows (the
    /// time derivative of the warp, as the blend weights the sides). Active where the density is.
    openvdb::Vec3SGrid::Ptr velocity;

    /// World units (the grids share one uniform linear transform).
    double voxelSize() const
    {
        return density ? density->voxelSize()[0] : sdf ? sdf->voxelSize()[0] : 0.0;
    }
};

/// A shape placed at one time of a morph (variational mode's influence shapes).
struct TimedVolume {
    VolumeSet volume;
    double t = 0.5;
};

/// Puts `grid` in the part of `volumes` its name gives (sdf, density, Cd, vel or Blender's
/// velocity; a part of another type is left empty); false for any other name.
inline bool setPartByName(VolumeSet& volumes, const openvdb::GridBase::Ptr& grid)
{
    const std::string& name = grid->getName();
    if (name == kSdfGridName)
        volumes.sdf = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
    else if (name == kDensityGridName)
        volumes.density = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
    else if (name == kColorGridName)
        volumes.color = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid);
    else if (name == kVelocityGridName || name == "velocity")
        volumes.velocity = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid);
    else
        return false;
    return true;
}

/// The grid names a .vdb is written with: volmorph's own (sdf, density, Cd, vel), Houdini's
/// (surface, density, Cd, vel) or Blender's (sdf, density, color, velocity). Carried grids keep
/// their names, but for vel / velocity, which each preset names its way.
enum class GridNames { Volmorph, Houdini, Blender };

struct VdbWriteOptions {
    GridNames names = GridNames::Volmorph;
    bool half = false; ///< float and vec3 grids stored as 16-bit floats
    /// String metadata added to every grid (frame, t, fps, ...).
    std::map<std::string, std::string> metadata;
};

/// The name `grid` (one of volmorph's names, or a carried grid's) is written with under `names`.
std::string presetName(const std::string& grid, GridNames names);

/// The grids that are set, extras included, as a file of `options` holds them: shallow copies (the
/// trees shared) named by the preset (a carried grid whose name a part takes gets "_carried"),
/// stored as half when asked, with the metadata.
openvdb::GridPtrVec namedGrids(const VolumeSet& volumes, const VdbWriteOptions& options = {});

/// Writes the grids that are set, extras included, named and stored as `options` says. The file
/// appears at `path` only when complete (written to a temporary name, then renamed). Throws
/// UserError naming the path when it cannot be written.
void writeVolumeSet(const VolumeSet& volumes, const std::filesystem::path& path,
                    const VdbWriteOptions& options = {});

/// Reads sdf, density, Cd and vel (or Blender's velocity) from a .vdb file (any that are present).
/// Throws UserError naming the file when it cannot be read.
VolumeSet readVolumeSet(const std::filesystem::path& path);

} // namespace volmorph
