// A volume file as an input of the volume stage (volmorph/VolumeInput.h): which file, which of its
// grids play which part, and how it is placed.
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>
#include <volmorph/core/ObjectTransform.h>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>

namespace volmorph {

/// Which grids of a volume input play which part. An empty name: the first of the defaults
/// (volmorph/VolumeInput.h) that the file holds.
struct VolumeGridNames {
    std::string density, sdf, color;
    SourceLocation where; ///< where the names were written (a scene's `grids` key), if anywhere
};

/// Whether `file` is a NIfTI volume (.nii or .nii.gz), by its name.
bool isNiftiFile(const std::filesystem::path& file);

struct VolumeSource {
    std::filesystem::path file; ///< a .vdb (fog or level set) or a NIfTI-1 .nii / .nii.gz
    VolumeGridNames grids;
    /// NIfTI only: the intensities [lo, hi] mapped to density 0..1 (clamped); unset: the file's
    /// cal_min..cal_max, else its data's range.
    std::optional<std::pair<double, double>> window;
    ObjectTransform transform;  ///< applied after the volume's own transform
    std::optional<Vec3d> color; ///< linear RGB, used when the file has no colour grid (else grey)
    SourceLocation where; ///< where the file was named, for errors on reading; empty: the file
};

} // namespace volmorph
