// Volume files -> VolumeSet: a .vdb's grids picked by name, checked, placed by the object's
// transform and resampled onto the scene's voxel grid with OpenVDB's tools.
//
// Which grid plays which part: the side's `grids` table names them; a part it leaves out takes the
// first of its defaults that the file holds (Houdini's and Blender's usual names):
//   density: "density";  sdf: "surface" (Houdini's VDB from Polygons), "sdf";  colour: "Cd"
//   (Houdini), "color" (Blender).
// Every other float or vec3 grid of the file is carried as an extra (VolumeSet::extras); grids of
// other types (int, bool, points) are left out, and inspectVolume() lists them.
//
// What a file lacks is derived, always the same way:
// - a level set alone: its density is the fog a mesh gets (fogFromLevelSet, Voxelize.h);
// - a fog alone, in density mode: nothing more. In sdf mode (`needSdf`): the level set of its
//   density at kFogSurfaceDensity (0.5, where a mesh's fog is on its surface), by OpenVDB's
//   levelSetRebuild (volumeToMesh at that value, then meshToVolume);
// - no colour grid: the object's colour (or grey) everywhere, an empty Cd with that background.
//
// Resampling: each grid is placed by its own transform followed by the object's (scale, rotate,
// translate), and resampled onto the scene's transform with tools::resampleToMatch: trilinear for
// fogs and vec3 grids, rebuilt as a level set for level sets (so a rotated or scaled level set
// stays a distance field). A grid already on the scene's transform is copied as it is. Vec3 grids
// are resampled as values: a rotation does not turn their vectors (right for colours; an input
// velocity grid would keep its old directions).
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/core/Math.h>
#include <volmorph/VolumeSource.h>
#include <volmorph/VolumeSet.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace volmorph {

namespace detail {
class VolumeFile;
}

/// The density a fog's derived surface passes through (sdf mode with a fog alone).
inline constexpr float kFogSurfaceDensity = 0.5f;

/// What a volume file holds and which of its grids play which part, read without its voxels.
struct VolumeFileInfo {
    std::string density, sdf, color;  ///< the picked grids' names (empty: none)
    std::vector<std::string> extras;  ///< every other float or vec3 grid, carried
    std::vector<std::string> ignored; ///< grids of other types, left out
    double voxelSize = 0.0;           ///< world units, under the object's transform (the finest of
                                      ///< the picked grids, its smallest scale)
    Vec3d worldMin{0.0}, worldMax{0.0}; ///< the picked grids' active bounds, world units
    bool empty = true;                  ///< no active voxel in the density or sdf grid
};

struct VolumeInputOptions {
    double voxelSize = 0.0; ///< the scene's, world units
    bool needSdf = false;   ///< sdf mode: a fog alone gets a derived level set
    /// Refuse to resample past this estimate of bytes; 0 = half the machine's memory.
    uint64_t memoryLimitBytes = 0;
};

/// One side's volume file, read whole once: what it holds, then its grids on the scene's
/// transform.
class VolumeInput {
public:
    /// Reads `source.file`, picks the parts and checks them. Throws UserError naming the file (at
    /// `source.where`) for a file that cannot be read (truncated or damaged), a named
    /// grid it lacks (with a "did you mean" from its grid names), a part of the wrong type, a
    /// frustum transform, or neither a density nor a level set.
    explicit VolumeInput(const VolumeSource& source);
    ~VolumeInput();
    VolumeInput(VolumeInput&&) noexcept;

    const VolumeFileInfo& info() const;

    /// The grids on the scene's transform (a linear transform of `options.voxelSize`, as
    /// voxelize() gives meshes): density and Cd always, sdf when the file has a level set or
    /// `needSdf`, and the extras. Throws UserError for NaN or infinite values or past the memory
    /// limit; Interrupted when `interrupter` asks to stop.
    VolumeSet resample(const VolumeInputOptions& options, Interrupter* interrupter = nullptr) const;

private:
    std::unique_ptr<detail::VolumeFile> mFile;
};

/// VolumeInput(source).info().
VolumeFileInfo inspectVolume(const VolumeSource& source);

} // namespace volmorph
