// Dense scans (CT, MRI) in NIfTI-1 or NIfTI-2 (.nii, .nii.gz), read with libnifti2, as one fog
// grid.
#pragma once

#include <openvdb/openvdb.h>

#include <filesystem>
#include <optional>
#include <utility>

namespace volmorph::detail {

/// The first 3D volume of a NIfTI file as one float grid "density" (a fog): each voxel's intensity
/// (the file's scl_slope and scl_inter applied) mapped through `window` [lo, hi] to 0..1, clamped;
/// active where above 0. Unset, the window is the file's cal_min..cal_max, else its intensities'
/// range. The transform is the file's sform, else its qform, else its voxel spacing: world units
/// are the file's (usually millimetres; the side's transform.scale converts them). Reads integer
/// and real scalar datatypes; throws std::runtime_error saying why for any other (complex, RGB),
/// and for a file libnifti2 cannot read.
openvdb::GridPtrVecPtr readNiftiGrids(const std::filesystem::path& path,
                                      const std::optional<std::pair<double, double>>& window);

} // namespace volmorph::detail
