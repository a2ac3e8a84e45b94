#include "blend/variational/Slice.h"

#include <openvdb/tools/Dense.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <array>
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

namespace {

/// Exact values on the lattice box.min + stride * (a, b, c), covering the box.
struct Lattice {
    openvdb::Coord origin;
    int stride = 1;
    openvdb::Coord nodes; ///< per axis
    std::vector<float> values;

    float at(int a, int b, int c) const
    {
        return values[(size_t(a) * nodes.y() + b) * nodes.z() + c];
    }

    /// Catmull-Rom between the nodes around cell (a, b, c) at (u, v, s) in [0, 1)^3 (nodes
    /// beyond the lattice clamped to its edge): exact for cubics along each axis, its error the
    /// function's fourth derivatives times stride^4.
    double tricubic(int a, int b, int c, double u, double v, double s) const
    {
        const auto weights = [](double x) {
            return std::array<double, 4>{
                0.5 * (-x * x * x + 2 * x * x - x), 0.5 * (3 * x * x * x - 5 * x * x + 2),
                0.5 * (-3 * x * x * x + 4 * x * x + x), 0.5 * (x * x * x - x * x)};
        };
        const auto wu = weights(u), wv = weights(v), ws = weights(s);
        const auto clampTo = [](int i, int n) { return std::clamp(i, 0, n - 1); };
        double value = 0.0;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                for (int k = 0; k < 4; ++k)
                    value += wu[i] * wv[j] * ws[k] *
                             at(clampTo(a + i - 1, nodes.x()), clampTo(b + j - 1, nodes.y()),
                                clampTo(c + k - 1, nodes.z()));
        return value;
    }
};

/// The lattice's values where `needed(a, b, c)` says (NaN elsewhere); `evaluations` counts them.
Lattice evaluateLattice(const std::function<double(const Point4&)>& f, double w,
                        const openvdb::math::Transform& transform, const openvdb::CoordBBox& box,
                        int stride, const std::function<bool(int, int, int)>& needed,
                        size_t& evaluations)
{
    Lattice l;
    l.origin = box.min();
    l.stride = stride;
    const openvdb::Coord dim = box.dim();
    for (int a = 0; a < 3; ++a) l.nodes[a] = (dim[a] - 1 + stride - 1) / stride + 1;
    l.values.assign(size_t(l.nodes.x()) * l.nodes.y() * l.nodes.z(),
                    std::numeric_limits<float>::quiet_NaN());
    std::atomic<size_t> count{0};
    tbb::parallel_for(0, l.nodes.x(), [&](int a) {
        size_t here = 0;
        for (int b = 0; b < l.nodes.y(); ++b)
            for (int c = 0; c < l.nodes.z(); ++c) {
                if (!needed(a, b, c)) continue;
                const openvdb::Vec3d p = transform.indexToWorld(
                    l.origin + openvdb::Coord(a * stride, b * stride, c * stride));
                l.values[(size_t(a) * l.nodes.y() + b) * l.nodes.z() + c] =
                    float(-f(Point4(p.x(), p.y(), p.z(), w)));
                ++here;
            }
        count += here;
    });
    evaluations += count;
    return l;
}

/// Whether lattice cell (a, b, c) can hold the zero set within `band` voxels of it.
bool nearZero(const Lattice& l, int a, int b, int c, double band)
{
    float lo = 1e30f, hi = -1e30f, smallest = 1e30f, steepest = 0.0f;
    for (int corner = 0; corner < 8; ++corner) {
        const int i = a + (corner >> 2), j = b + ((corner >> 1) & 1), k = c + (corner & 1);
        const float v = l.at(i, j, k);
        lo = std::min(lo, v), hi = std::max(hi, v), smallest = std::min(smallest, std::abs(v));
        if (i > a) steepest = std::max(steepest, std::abs(v - l.at(a, j, k)));
        if (j > b) steepest = std::max(steepest, std::abs(v - l.at(i, b, k)));
        if (k > c) steepest = std::max(steepest, std::abs(v - l.at(i, j, c)));
    }
    if (lo <= 0.0f && hi >= 0.0f) return true;
    // The steepest edge's slope per voxel, over the cell's diagonal and the band.
    const double slope = steepest / double(l.stride);
    return smallest <= slope * (std::sqrt(3.0) * l.stride + band);
}

/// Cells of `l` near the zero set (nearZero), grown by `grow` cells each way.
std::vector<char> cellsNearZero(const Lattice& l, double band, int grow)
{
    const openvdb::Coord cells = l.nodes - openvdb::Coord(1);
    const auto index = [&](int a, int b, int c) {
        return (size_t(a) * cells.y() + b) * cells.z() + c;
    };
    std::vector<char> near(size_t(cells.x()) * cells.y() * cells.z(), 0);
    for (int a = 0; a < cells.x(); ++a)
        for (int b = 0; b < cells.y(); ++b)
            for (int c = 0; c < cells.z(); ++c) {
                if (!nearZero(l, a, b, c, band)) continue;
                for (int i = std::max(0, a - grow); i <= std::min(cells.x() - 1, a + grow); ++i)
                    for (int j = std::max(0, b - grow); j <= std::min(cells.y() - 1, b + grow); ++j)
                        for (int k = std::max(0, c - grow); k <= std::min(cells.z() - 1, c + grow);
                             ++k)
                            near[index(i, j, k)] = 1;
            }
    return near;
}

} // namespace

openvdb::FloatGrid::Ptr sliceNearZero(const std::function<double(const Point4&)>& f, double w,
                                      const openvdb::math::Transform::Ptr& transform,
                                      const openvdb::CoordBBox& box, int stride, double bandVoxels,
                                      size_t* evaluations)
{
    // Screening: exact values every 4 strides; the fine lattice only in the coarse cells near the
    // zero set, grown by two (a fine cell's tricubic reads a node beyond it).
    const int coarseStride = 4 * stride;
    size_t count = 0;
    const Lattice coarse = evaluateLattice(
        f, w, *transform, box, coarseStride, [](int, int, int) { return true; }, count);
    const std::vector<char> nodesNear = cellsNearZero(coarse, bandVoxels, 2);
    const std::vector<char> cellsNear = cellsNearZero(coarse, bandVoxels, 1);
    const openvdb::Coord coarseCells = coarse.nodes - openvdb::Coord(1);
    const auto coarseCell = [&](const std::vector<char>& near, int a, int b, int c) {
        const int i = std::min(a / 4, coarseCells.x() - 1),
                  j = std::min(b / 4, coarseCells.y() - 1),
                  k = std::min(c / 4, coarseCells.z() - 1);
        return bool(near[(size_t(i) * coarseCells.y() + j) * coarseCells.z() + k]);
    };
    const Lattice l = evaluateLattice(
        f, w, *transform, box, stride,
        [&](int a, int b, int c) { return coarseCell(nodesNear, a, b, c); }, count);
    if (evaluations) *evaluations = count;
    const openvdb::Coord cells = l.nodes - openvdb::Coord(1);
    std::vector<char> kept(size_t(cells.x()) * cells.y() * cells.z(), 0);
    const auto index = [&](int a, int b, int c) {
        return (size_t(a) * cells.y() + b) * cells.z() + c;
    };
    for (int a = 0; a < cells.x(); ++a)
        for (int b = 0; b < cells.y(); ++b)
            for (int c = 0; c < cells.z(); ++c)
                if (coarseCell(cellsNear, a, b, c) && nearZero(l, a, b, c, bandVoxels))
                    kept[index(a, b, c)] = 1;
    auto grid = openvdb::FloatGrid::create(float(bandVoxels * transform->voxelSize()[0]));
    auto acc = grid->getAccessor();
    for (int a = 0; a < cells.x(); ++a)
        for (int b = 0; b < cells.y(); ++b)
            for (int c = 0; c < cells.z(); ++c) {
                bool any = false; // the cell or a neighbour kept
                for (int da = -1; da <= 1 && !any; ++da)
                    for (int db = -1; db <= 1 && !any; ++db)
                        for (int dc = -1; dc <= 1 && !any; ++dc) {
                            const int i = a + da, j = b + db, k = c + dc;
                            any = i >= 0 && j >= 0 && k >= 0 && i < cells.x() && j < cells.y() &&
                                  k < cells.z() && kept[index(i, j, k)];
                        }
                if (!any) continue;
                for (int x = 0; x < stride; ++x)
                    for (int y = 0; y < stride; ++y)
                        for (int z = 0; z < stride; ++z)
                            acc.setValue(l.origin + openvdb::Coord(a * stride + x, b * stride + y,
                                                                   c * stride + z),
                                         float(l.tricubic(a, b, c, double(x) / stride,
                                                          double(y) / stride, double(z) / stride)));
            }
    grid->setTransform(transform);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return grid;
}

} // namespace volmorph::detail::variational
