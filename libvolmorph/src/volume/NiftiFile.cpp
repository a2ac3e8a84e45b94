#include "volume/NiftiFile.h"

#include <volmorph/VolumeSource.h>

#include <openvdb/tools/Dense.h>

#include <nifti2_io.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace volmorph {

bool isNiftiFile(const std::filesystem::path& file)
{
    const std::string name = file.filename().string();
    auto endsWith = [&name](const std::string& end) {
        return name.size() >= end.size() &&
               name.compare(name.size() - end.size(), end.size(), end) == 0;
    };
    return endsWith(".nii") || endsWith(".nii.gz");
}

} // namespace volmorph

namespace volmorph::detail {

namespace {

struct NiftiDeleter {
    void operator()(nifti_image* image) const { nifti_image_free(image); }
};
using NiftiImage = std::unique_ptr<nifti_image, NiftiDeleter>;

template <typename T>
void convert(const void* data, std::vector<float>& out)
{
    const T* in = static_cast<const T*>(data);
    for (size_t i = 0; i < out.size(); ++i) out[i] = float(in[i]);
}

/// The first volume's intensities as floats, before scaling. False for a datatype that is not an
/// integer or real scalar.
bool intensities(const nifti_image& image, std::vector<float>& out)
{
    using Convert = void (*)(const void*, std::vector<float>&);
    static const std::pair<int, Convert> kConverters[] = {
        {DT_UINT8, convert<uint8_t>}, {DT_INT8, convert<int8_t>},
        {DT_INT16, convert<int16_t>}, {DT_UINT16, convert<uint16_t>},
        {DT_INT32, convert<int32_t>}, {DT_UINT32, convert<uint32_t>},
        {DT_INT64, convert<int64_t>}, {DT_UINT64, convert<uint64_t>},
        {DT_FLOAT32, convert<float>}, {DT_FLOAT64, convert<double>}};
    for (const auto& [code, to] : kConverters)
        if (image.datatype == code) {
            to(image.data, out);
            return true;
        }
    return false;
}

/// Index (i, j, k) to world: the sform, else the qform, else the voxel spacing.
openvdb::math::Transform::Ptr transformOf(const nifti_image& image)
{
    const nifti_dmat44* m = image.sform_code > 0   ? &image.sto_xyz
                            : image.qform_code > 0 ? &image.qto_xyz
                                                   : nullptr;
    if (!m) {
        openvdb::math::Mat4d scale = openvdb::math::Mat4d::identity();
        scale.preScale(openvdb::Vec3d(std::abs(image.dx) > 0 ? std::abs(image.dx) : 1.0,
                                      std::abs(image.dy) > 0 ? std::abs(image.dy) : 1.0,
                                      std::abs(image.dz) > 0 ? std::abs(image.dz) : 1.0));
        return openvdb::math::Transform::createLinearTransform(scale);
    }
    // NIfTI's matrices act on column vectors, OpenVDB's on row vectors: transposed.
    openvdb::math::Mat4d rows;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) rows(c, r) = m->m[r][c];
    return openvdb::math::Transform::createLinearTransform(rows);
}

} // namespace

openvdb::GridPtrVecPtr readNiftiGrids(const std::filesystem::path& path,
                                      const std::optional<std::pair<double, double>>& window)
{
    nifti_set_debug_level(0); // its messages would go to stderr; volmorph reports its own
    const NiftiImage image(nifti_image_read(path.string().c_str(), /*read_data=*/1));
    if (!image || !image->data)
        throw std::runtime_error("libnifti2 cannot read it as a NIfTI-1 or NIfTI-2 volume");
    const int64_t nx = std::max<int64_t>(1, image->nx), ny = std::max<int64_t>(1, image->ny),
                  nz = std::max<int64_t>(1, image->nz);
    std::vector<float> values(size_t(nx * ny * nz));
    if (!intensities(*image, values))
        throw std::runtime_error(std::string("its datatype is ") +
                                 nifti_datatype_string(image->datatype) +
                                 "; volmorph reads integer and real scalar volumes");
    const bool scaled = image->scl_slope != 0.0;
    for (float& v : values)
        if (scaled) v = float(image->scl_slope * v + image->scl_inter);
    double lo, hi;
    if (window) {
        std::tie(lo, hi) = *window;
    } else if (image->cal_max > image->cal_min) {
        lo = image->cal_min;
        hi = image->cal_max;
    } else {
        const auto [a, b] = std::minmax_element(values.begin(), values.end());
        lo = *a;
        hi = *b > *a ? double(*b) : double(*a) + 1.0;
    }
    for (float& v : values) v = float(std::clamp((double(v) - lo) / (hi - lo), 0.0, 1.0));
    const openvdb::CoordBBox box(openvdb::Coord(0),
                                 openvdb::Coord(int(nx - 1), int(ny - 1), int(nz - 1)));
    const openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, values.data());
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    openvdb::tools::copyFromDense(dense, *grid, /*tolerance=*/0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(transformOf(*image));
    auto grids = std::make_shared<openvdb::GridPtrVec>();
    grids->push_back(grid);
    return grids;
}

} // namespace volmorph::detail
