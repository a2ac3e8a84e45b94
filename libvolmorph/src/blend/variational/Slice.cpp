#include "blend/variational/Slice.h"

#include <openvdb/tools/Dense.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace volmorph::detail::variational {

openvdb::FloatGrid::Ptr sliceOverBox(const std::function<double(const Point4&)>& f, double w,
                                     const openvdb::math::Transform::Ptr& transform,
                                     const openvdb::CoordBBox& box)
{
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box);
    const openvdb::Coord size = box.dim();
    tbb::parallel_for(box.min().x(), box.max().x() + 1, [&](int i) {
        for (int j = box.min().y(); j <= box.max().y(); ++j)
            for (int k = box.min().z(); k <= box.max().z(); ++k) {
                const openvdb::Vec3d p = transform->indexToWorld(openvdb::Coord(i, j, k));
                dense.setValue(openvdb::Coord(i, j, k), float(-f(Point4(p.x(), p.y(), p.z(), w))));
            }
    });
    float largest = 0.0f;
    const float* data = dense.data();
    for (size_t n = 0; n < size_t(size.x()) * size.y() * size.z(); ++n)
        largest = std::max(largest, std::abs(data[n]));
    auto grid = openvdb::FloatGrid::create(largest);
    openvdb::tools::copyFromDense(dense, *grid, 0.0f);
    // copyFromDense makes voxels equal to the background inactive: every voxel of the box counts.
    grid->tree().voxelizeActiveTiles();
    for (auto it = grid->tree().beginLeaf(); it; ++it) it->setValuesOn();
    grid->setTransform(transform);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return grid;
}

} // namespace volmorph::detail::variational
