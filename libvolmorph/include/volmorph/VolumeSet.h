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

    /// World units (the grids share one uniform linear transform).
    double voxelSize() const
    {
        return density ? density->voxelSize()[0] : sdf ? sdf->voxelSize()[0] : 0.0;
    }
};

/// Writes the grids that are set, extras included, with `metadata` added to each as string
/// metadata. The file appears at `path` only when complete (written to a temporary name, then
/// renamed). Throws UserError naming the path when it cannot be written.
void writeVolumeSet(const VolumeSet& volumes, const std::filesystem::path& path,
                    const std::map<std::string, std::string>& metadata = {});

/// Reads sdf, density and Cd from a .vdb file (any that are present). Throws UserError naming the
/// file when it cannot be read.
VolumeSet readVolumeSet(const std::filesystem::path& path);

} // namespace volmorph
