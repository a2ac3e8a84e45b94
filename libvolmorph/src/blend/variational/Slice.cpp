#include "blend/variational/Slice.h"

#include <openvdb/tools/Dense.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <array>
#include <cmath>
#include <optional>

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

using openvdb::Coord;

/// Exact values (and rates) on the lattice box.min + stride * (a, b, c), covering the box, at the
/// nodes `evaluated` marks.
struct Lattice {
    Coord origin;
    int stride = 1;
    Coord nodes; ///< per axis
    std::vector<float> values, rates;
    std::vector<char> evaluated; ///< per node

    size_t node(int a, int b, int c) const { return (size_t(a) * nodes.y() + b) * nodes.z() + c; }
    float at(int a, int b, int c) const { return values[node(a, b, c)]; }
    Coord cells() const { return nodes - Coord(1); }

    /// Catmull-Rom in `field` between the nodes around cell (a, b, c), with weights `w` per axis
    /// (nodes beyond the lattice clamped to its edge): exact for cubics along each axis, its error
    /// the function's fourth derivatives times stride^4. Nodes of zero weight (all but one along
    /// an axis where the point is on a node) are not read. With `complete`, a read of a node not
    /// evaluated sets it false and ends the sum (its value then means nothing).
    double tricubic(const std::vector<float>& field, int a, int b, int c,
                    const std::array<std::array<double, 4>, 3>& w, bool* complete = nullptr) const
    {
        const auto clampTo = [](int i, int n) { return std::clamp(i, 0, n - 1); };
        double value = 0.0;
        for (int i = 0; i < 4; ++i) {
            if (w[0][i] == 0.0) continue;
            for (int j = 0; j < 4; ++j) {
                if (w[1][j] == 0.0) continue;
                double row = 0.0;
                const size_t base = (size_t(clampTo(a + i - 1, nodes.x())) * nodes.y() +
                                     size_t(clampTo(b + j - 1, nodes.y()))) *
                                    nodes.z();
                for (int k = 0; k < 4; ++k)
                    if (w[2][k] != 0.0) {
                        const size_t n = base + size_t(clampTo(c + k - 1, nodes.z()));
                        if (complete && !evaluated[n]) {
                            *complete = false;
                            return 0.0;
                        }
                        row += w[2][k] * field[n];
                    }
                value += w[0][i] * w[1][j] * row;
            }
        }
        return value;
    }

    /// The cell holding voxel `v` (index space relative to the origin, inside the lattice) and
    /// the voxel's Catmull-Rom weights in it.
    std::pair<Coord, std::array<std::array<double, 4>, 3>> cellOf(const Coord& v) const;
};

std::array<double, 4> catmullRom(double x)
{
    return {0.5 * (-x * x * x + 2 * x * x - x), 0.5 * (3 * x * x * x - 5 * x * x + 2),
            0.5 * (-3 * x * x * x + 4 * x * x + x), 0.5 * (x * x * x - x * x)};
}

std::pair<Coord, std::array<std::array<double, 4>, 3>> Lattice::cellOf(const Coord& v) const
{
    Coord cell;
    std::array<std::array<double, 4>, 3> weights;
    for (int axis = 0; axis < 3; ++axis) {
        cell[axis] = std::max(0, std::min(v[axis] / stride, nodes[axis] - 2));
        weights[axis] = catmullRom(double(v[axis] - cell[axis] * stride) / stride);
    }
    return {cell, weights};
}

/// f at a lattice node: its voxel (index space, relative to the lattice's origin) and its point.
using NodeFunction = std::function<double(const Coord& voxel, const Point4& p, double* rate)>;

/// A lattice over `box` at `stride`, no node evaluated yet.
Lattice emptyLattice(const openvdb::CoordBBox& box, int stride, bool withRates)
{
    Lattice l;
    l.origin = box.min();
    l.stride = stride;
    const Coord dim = box.dim();
    for (int a = 0; a < 3; ++a) l.nodes[a] = (dim[a] - 1 + stride - 1) / stride + 1;
    const size_t count = size_t(l.nodes.x()) * l.nodes.y() * l.nodes.z();
    l.values.assign(count, 0.0f);
    l.evaluated.assign(count, 0);
    if (withRates) l.rates.assign(count, 0.0f);
    return l;
}

/// -f (and -df/dw, when the lattice holds rates) at the nodes `needed` marks and not yet
/// evaluated; `evaluations` counts them.
void evaluateNodes(Lattice& l, const NodeFunction& f, double w,
                   const openvdb::math::Transform& transform, const std::vector<char>& needed,
                   size_t& evaluations, Interrupter* interrupter)
{
    const bool withRates = !l.rates.empty();
    std::atomic<size_t> taken{0};
    std::atomic<bool> stopped{false};
    tbb::parallel_for(0, l.nodes.x(), [&](int a) {
        if (stopped || (interrupter && interrupter->wasInterrupted())) {
            stopped = true;
            return;
        }
        size_t here = 0;
        for (int b = 0; b < l.nodes.y(); ++b)
            for (int c = 0; c < l.nodes.z(); ++c) {
                const size_t n = l.node(a, b, c);
                if (!needed[n] || l.evaluated[n]) continue;
                const Coord v(a * l.stride, b * l.stride, c * l.stride);
                const openvdb::Vec3d p = transform.indexToWorld(l.origin + v);
                double rate = 0.0;
                l.values[n] =
                    float(-f(v, Point4(p.x(), p.y(), p.z(), w), withRates ? &rate : nullptr));
                if (withRates) l.rates[n] = float(-rate);
                l.evaluated[n] = 1;
                ++here;
            }
        taken += here;
    });
    if (stopped) throw Interrupted();
    evaluations += taken;
}

/// Whether lattice cell (a, b, c) can hold the zero set within `band` voxels of it: its corners
/// change sign, or the smallest is within the band and an allowance at the steepest slope between
/// them (never taken under `leastSlope` per voxel, about a distance's: f is flat between the
/// shapes in places). Were f linear across the cell its smallest |f| would be at a corner; the
/// allowance is for its curvature: across a cell of side s, f leaves its multilinear interpolant
/// by about s^2 / 8 times its second derivative, which for a distance is one over the radius of
/// curvature, and the grid resolves no radius under a voxel: s^2 / 8 voxels, and never over a
/// stride (BENCHMARKS.md, the variational method: what other allowances kept and lost). The
/// corners are evaluated (the level evaluates the corners of every cell it tests).
bool nearZero(const Lattice& l, int a, int b, int c, double band, double leastSlope)
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
    // The steepest edge's slope per voxel, over the band and the allowance.
    const double slope = std::max(double(steepest) / l.stride, leastSlope);
    const double allowance = std::min(double(l.stride), l.stride * l.stride / 8.0);
    return smallest <= slope * (band + allowance);
}

/// A mask over a lattice's cells.
struct CellMask {
    Coord cells;
    std::vector<char> on;

    bool at(int a, int b, int c) const { return on[(size_t(a) * cells.y() + b) * cells.z() + c]; }
    /// Whether the cell of this mask holding the cell (a, b, c) of a lattice `ratio` times finer
    /// is on.
    bool holds(int a, int b, int c, int ratio) const
    {
        return at(std::min(a / ratio, cells.x() - 1), std::min(b / ratio, cells.y() - 1),
                  std::min(c / ratio, cells.z() - 1));
    }
};

/// The cells of a lattice with `cells` cells per axis where `on(a, b, c)` holds.
template <typename On>
CellMask cellsWhere(const Coord& cells, On on)
{
    CellMask m{cells, std::vector<char>(size_t(cells.x()) * cells.y() * cells.z(), 0)};
    for (int a = 0; a < cells.x(); ++a)
        for (int b = 0; b < cells.y(); ++b)
            for (int c = 0; c < cells.z(); ++c)
                m.on[(size_t(a) * cells.y() + b) * cells.z() + c] = on(a, b, c);
    return m;
}

/// Cells of `l` near the zero set (nearZero) among the `candidates`.
CellMask cellsNearZero(const Lattice& l, double band, double leastSlope, const CellMask& candidates)
{
    return cellsWhere(l.cells(), [&](int a, int b, int c) {
        return candidates.at(a, b, c) && nearZero(l, a, b, c, band, leastSlope);
    });
}

/// The nodes (a mask over them) of the cells of `m` and `reach` nodes further on each side (1: each
/// cell's Catmull-Rom stencil; 2: the stencils of the cells and their neighbours).
std::vector<char> nodesOf(const CellMask& m, int reach)
{
    const Coord n = m.cells + Coord(1);
    std::vector<char> nodes(size_t(n.x()) * n.y() * n.z(), 0);
    for (int a = 0; a < m.cells.x(); ++a)
        for (int b = 0; b < m.cells.y(); ++b)
            for (int c = 0; c < m.cells.z(); ++c) {
                if (!m.at(a, b, c)) continue;
                for (int i = std::max(0, a - reach); i <= std::min(n.x() - 1, a + 1 + reach); ++i)
                    for (int j = std::max(0, b - reach); j <= std::min(n.y() - 1, b + 1 + reach);
                         ++j)
                        for (int k = std::max(0, c - reach);
                             k <= std::min(n.z() - 1, c + 1 + reach); ++k)
                            nodes[(size_t(i) * n.y() + j) * n.z() + k] = 1;
            }
    return nodes;
}

/// The cells of lattice `l` inside the cells of `parent` (a lattice `ratio` times coarser).
CellMask children(const CellMask& parent, const Lattice& l, int ratio)
{
    return cellsWhere(l.cells(), [&](int a, int b, int c) { return parent.holds(a, b, c, ratio); });
}

/// The fine lattice's values (and rates) where the screening keeps cells: levels `kRatio` times
/// coarser each, the coarsest over the whole box.
constexpr int kLevels = 5, kRatio = 2;

struct Screened {
    Lattice fine;
    CellMask kept; ///< the fine lattice's cells near the zero set
};

/// A smooth part on a lattice at `stride`, exact at the nodes of the stencils of the `cells` and
/// their neighbours (which hold every node of the finer levels).
Lattice smoothLattice(const SliceFunction& f, double w, const openvdb::math::Transform& transform,
                      const openvdb::CoordBBox& box, int stride, const CellMask& cells,
                      bool withRates, size_t& evaluations, Interrupter* interrupter)
{
    Lattice smooth = emptyLattice(box, stride, withRates);
    const NodeFunction exact = [&f](const Coord&, const Point4& p, double* rate) {
        return f(p, rate);
    };
    evaluateNodes(smooth, exact, w, transform, nodesOf(cells, 2), evaluations, interrupter);
    return smooth;
}

/// f at a node: the detail and every smooth part exactly, but those whose lattice `lattices`
/// holds (tricubic there).
double splitValue(const SplitFunction& f, const std::vector<Lattice>& lattices, const Coord& v,
                  const Point4& p, double* rate)
{
    double value = f.detail(p, rate);
    for (size_t k = 0; k < f.smooth.size(); ++k) {
        const Lattice& l = lattices[k];
        std::optional<double> part;
        double partRate = 0.0;
        if (!l.values.empty()) {
            const auto [cell, weights] = l.cellOf(v);
            bool complete = true;
            const double read =
                -l.tricubic(l.values, cell.x(), cell.y(), cell.z(), weights, &complete);
            if (complete) {
                part = read;
                if (rate && !l.rates.empty())
                    partRate = -l.tricubic(l.rates, cell.x(), cell.y(), cell.z(), weights);
            }
        }
        // Not read from a lattice (yet), or (never) off its stencils: exact.
        if (!part) part = f.smooth[k].f(p, rate ? &partRate : nullptr);
        value += *part;
        if (rate) *rate += partRate;
    }
    return value;
}

Screened screen(const SplitFunction& f, double w, const openvdb::math::Transform& transform,
                const openvdb::CoordBBox& box, int stride, double band, bool withRates,
                size_t& evaluations, Interrupter* interrupter)
{
    const double leastSlope = transform.voxelSize()[0]; // a distance's, per voxel
    int levelStride = stride;
    for (int level = 1; level < kLevels; ++level) levelStride *= kRatio;
    // Each smooth part exact until the levels finer than its stride read it from its lattice.
    std::vector<Lattice> lattices(f.smooth.size());
    const NodeFunction value = [&](const Coord& v, const Point4& p, double* rate) {
        return splitValue(f, lattices, v, p, rate);
    };
    CellMask kept;
    for (int level = 0;; ++level, levelStride /= kRatio) {
        const bool last = level == kLevels - 1;
        Lattice l = emptyLattice(box, levelStride, last && withRates);
        // The cells tested: every one at first, then those inside the cells kept a level up.
        CellMask candidates = level == 0 ? cellsWhere(l.cells(), [](int, int, int) { return true; })
                                         : children(kept, l, kRatio);
        evaluateNodes(l, value, w, transform, nodesOf(candidates, 0), evaluations, interrupter);
        kept = cellsNearZero(l, band, leastSlope, candidates);
        if (last) {
            // The kept cells' voxels are interpolated: their stencils' nodes too.
            evaluateNodes(l, value, w, transform, nodesOf(kept, 1), evaluations, interrupter);
            return Screened{l, std::move(kept)};
        }
        for (size_t k = 0; k < f.smooth.size(); ++k)
            if (f.smooth[k].stride == levelStride)
                lattices[k] = smoothLattice(f.smooth[k].f, w, transform, box, levelStride, kept,
                                            withRates, evaluations, interrupter);
    }
}

/// The leaves (their origins, in order) holding voxels of the `written` cells.
std::vector<Coord> leavesWritten(const Lattice& l, const CellMask& written,
                                 const openvdb::CoordBBox& box)
{
    const Coord lo(box.min().x() >> 3, box.min().y() >> 3, box.min().z() >> 3);
    const Coord hi(box.max().x() >> 3, box.max().y() >> 3, box.max().z() >> 3);
    const Coord dim = hi - lo + Coord(1);
    std::vector<char> mark(size_t(dim.x()) * dim.y() * dim.z(), 0);
    const Coord cells = l.cells();
    for (int a = 0; a < cells.x(); ++a)
        for (int b = 0; b < cells.y(); ++b)
            for (int c = 0; c < cells.z(); ++c) {
                if (!written.at(a, b, c)) continue;
                // The cell's voxels, clipped to the box, in leaves.
                Coord first, last;
                const int abc[3] = {a, b, c};
                for (int axis = 0; axis < 3; ++axis) {
                    const int v0 = l.origin[axis] + abc[axis] * l.stride;
                    const int v1 = l.origin[axis] + (abc[axis] + 1) * l.stride - 1;
                    first[axis] = (std::max(v0, box.min()[axis]) >> 3) - lo[axis];
                    last[axis] = (std::min(v1, box.max()[axis]) >> 3) - lo[axis];
                }
                for (int i = first.x(); i <= last.x(); ++i)
                    for (int j = first.y(); j <= last.y(); ++j)
                        for (int k = first.z(); k <= last.z(); ++k)
                            mark[(size_t(i) * dim.y() + j) * dim.z() + k] = 1;
            }
    std::vector<Coord> origins;
    for (int i = 0; i < dim.x(); ++i)
        for (int j = 0; j < dim.y(); ++j)
            for (int k = 0; k < dim.z(); ++k)
                if (mark[(size_t(i) * dim.y() + j) * dim.z() + k])
                    origins.push_back(Coord((lo.x() + i) * 8, (lo.y() + j) * 8, (lo.z() + k) * 8));
    return origins;
}

} // namespace

NearZeroSlice sliceNearZero(const SliceFunction& f, double w,
                            const openvdb::math::Transform::Ptr& transform,
                            const openvdb::CoordBBox& box, int stride, double bandVoxels,
                            bool withRates, Interrupter* interrupter)
{
    return sliceNearZero(SplitFunction{{}, f}, w, transform, box, stride, bandVoxels, withRates,
                         interrupter);
}

NearZeroSlice sliceNearZero(const SplitFunction& f, double w,
                            const openvdb::math::Transform::Ptr& transform,
                            const openvdb::CoordBBox& box, int stride, double bandVoxels,
                            bool withRates, Interrupter* interrupter)
{
    NearZeroSlice out;
    const Screened s =
        screen(f, w, *transform, box, stride, bandVoxels, withRates, out.evaluations, interrupter);
    const Lattice& l = s.fine;
    const Coord cells = l.cells();
    // A voxel is written when its cell is kept; leaf by leaf, in parallel.
    const CellMask& written = s.kept;
    const std::vector<Coord> origins = leavesWritten(l, written, box);
    using Leaf = openvdb::FloatTree::LeafNodeType;
    std::vector<std::unique_ptr<Leaf>> values(origins.size()), rates(origins.size());
    const float background = float(bandVoxels * transform->voxelSize()[0]);
    // Catmull-Rom weights by a voxel's offset in its cell.
    std::vector<std::array<double, 4>> weightsAt(static_cast<size_t>(stride));
    for (int k = 0; k < stride; ++k) weightsAt[size_t(k)] = catmullRom(double(k) / stride);
    tbb::parallel_for(size_t(0), origins.size(), [&](size_t n) {
        auto value = std::make_unique<Leaf>(origins[n], background, false);
        auto rate = withRates ? std::make_unique<Leaf>(origins[n], 0.0f, false) : nullptr;
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
            const Coord v = origins[n] + Leaf::offsetToLocalCoord(i) - l.origin;
            if (!box.isInside(v + l.origin)) continue;
            const int a = v.x() / stride, b = v.y() / stride, c = v.z() / stride;
            if (a >= cells.x() || b >= cells.y() || c >= cells.z() || !written.at(a, b, c))
                continue;
            const std::array<std::array<double, 4>, 3> weights{
                weightsAt[size_t(v.x() - a * stride)], weightsAt[size_t(v.y() - b * stride)],
                weightsAt[size_t(v.z() - c * stride)]};
            // A written cell's stencil is evaluated (screen() evaluates nodesOf(kept, 2)).
            value->setValueOn(i, float(l.tricubic(l.values, a, b, c, weights)));
            if (rate) rate->setValueOn(i, float(l.tricubic(l.rates, a, b, c, weights)));
        }
        values[n] = std::move(value);
        rates[n] = std::move(rate);
    });
    out.values = openvdb::FloatGrid::create(background);
    for (auto& leaf : values)
        if (!leaf->isEmpty()) out.values->tree().addLeaf(leaf.release());
    out.values->setTransform(transform);
    out.values->setGridClass(openvdb::GRID_LEVEL_SET);
    if (withRates) {
        out.rates = openvdb::FloatGrid::create(0.0f);
        for (auto& leaf : rates)
            if (!leaf->isEmpty()) out.rates->tree().addLeaf(leaf.release());
        out.rates->setTransform(transform);
    }
    return out;
}

} // namespace volmorph::detail::variational
