#include "ShadowColumns.h"

#include "CellWalk.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace volmorph::render {

namespace {
/// Rays marched before their values are packed: bounds the unpacked copies held at once.
constexpr size_t kBatch = size_t(1) << 16;

/// Steps (of `spacing` world units) from a ray's start to its first prop: -inf when one lies
/// between the light (`lightBehind` behind the start) and the start, +inf when none does before
/// `length`.
float darkFrom(const Props& props, const Vec3d& start, const Vec3d& direction, double length,
               double spacing, double lightBehind)
{
    if (lightBehind > 0.0 && props.occluded(start, -direction, 0.0, lightBehind))
        return -std::numeric_limits<float>::infinity();
    PropHit hit;
    if (!props.intersect(start, direction, 0.0, length, hit))
        return std::numeric_limits<float>::infinity();
    return float(hit.distance / spacing);
}
} // namespace

std::array<Vec3d, 8> occupiedCorners(const openvdb::FloatGrid& density,
                                     const openvdb::BoolGrid& mask)
{
    const openvdb::CoordBBox box = mask.evalActiveVoxelBoundingBox();
    std::array<Vec3d, 8> corners;
    for (int c = 0; c < 8; ++c)
        corners[size_t(c)] =
            density.indexToWorld(Vec3d((c & 1) ? box.max().x() + 1.0 : box.min().x() - 1.0,
                                       (c & 2) ? box.max().y() + 1.0 : box.min().y() - 1.0,
                                       (c & 4) ? box.max().z() + 1.0 : box.min().z() - 1.0));
    return corners;
}

ShadowColumns::ShadowColumns(const MarchInputs& in, size_t count, const RayOf& rayOf, double length,
                             double spacing, double lightBehind)
{
    mSpans.reserve(count);
    const Intersector master(in.mask);
    std::vector<Column> columns;
    for (size_t first = 0; first < count; first += kBatch) {
        if (in.interrupter && in.interrupter->wasInterrupted()) return;
        columns.assign(std::min(kBatch, count - first), Column());
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, columns.size(), 64),
            [&](const tbb::blocked_range<size_t>& range) {
                Intersector inter(master);
                DensityReader acc(in.density.tree(), in.padded);
                std::vector<float> steps;
                for (size_t c = range.begin(); c != range.end(); ++c) {
                    if (in.interrupter && in.interrupter->wasInterrupted()) return;
                    Vec3d start, direction;
                    rayOf(first + c, start, direction);
                    march(inter, acc, in, start, direction, length, spacing, columns[c], steps);
                    compress(steps, columns[c]);
                    if (in.props)
                        columns[c].dark =
                            darkFrom(*in.props, start, direction, length, spacing, lightBehind);
                }
            });
        pack(columns);
    }
}

void ShadowColumns::pack(std::vector<Column>& columns)
{
    for (Column& col : columns) {
        mSpans.push_back(Span{col.first, int(col.knots.size()), col.last, col.dark, mKnots.size()});
        mKnots.insert(mKnots.end(), col.knots.begin(), col.knots.end());
        std::vector<Knot>().swap(col.knots);
    }
}

void ShadowColumns::march(Intersector& inter, DensityReader& acc, const MarchInputs& in,
                          const Vec3d& start, const Vec3d& direction, double length, double spacing,
                          Column& column, std::vector<float>& steps)
{
    steps.clear();
    if (!inter.setWorldRay(VdbRay(start, direction, 0.0, length))) return;
    const Medium1D ray{inter.getIndexPos(0.0), inter.getIndexPos(1.0) - inter.getIndexPos(0.0),
                       in.levelSet};
    // Index time per step (the index ray has unit speed in voxels).
    const double h = inter.getWorldTime(1.0) > 0.0 ? spacing / inter.getWorldTime(1.0) : spacing;
    double tau = 0.0, t0 = 0.0, t1 = 0.0;
    int k = -1; // the last step index stored
    auto push = [&] {
        steps.push_back(float(std::exp(-tau)));
        ++k;
    };
    bool going = true;
    while (going && inter.march(t0, t1)) {
        if (k < 0) { // nothing is absorbed before the first span: the column starts there
            column.first = int(std::floor(t0 / h));
            k = column.first - 1;
        }
        going = walkCells(acc, ray, t0, t1, [&](const Cell& cell, double ta, double tb) {
            // Split the piece at the steps inside it.
            for (double tk = (k + 1) * h; tk <= tb; tk = (k + 1) * h) {
                if (tk > ta) {
                    tau += in.sigmaPerVoxel * ray.mass(cell, ta, tk);
                    ta = tk;
                }
                push();
            }
            tau += in.sigmaPerVoxel * ray.mass(cell, ta, tb);
            return tau <= kMaxOpticalDepth + 2.0;
        });
        while ((k + 1) * h <= t1) push();
    }
    column.last = float(std::exp(-tau));
}

void ShadowColumns::compress(const std::vector<float>& steps, Column& column)
{
    const int n = int(std::min<size_t>(steps.size(), 65535));
    if (n == 0) return;
    auto keep = [&](int i) {
        column.knots.push_back(
            Knot{uint16_t(i), uint16_t(std::lround(double(steps[size_t(i)]) * 65535.0))});
    };
    // A segment from knot i0 may end at step j while its slope lies within the cone of every
    // step between (the slopes that pass within kTolerance of it).
    keep(0);
    int i0 = 0;
    double lo = -1e30, hi = 1e30;
    for (int j = 1; j < n; ++j) {
        const double slope =
            (double(steps[size_t(j)]) - double(steps[size_t(i0)])) / double(j - i0);
        if (slope < lo || slope > hi) {
            keep(j - 1);
            i0 = j - 1;
            lo = -1e30;
            hi = 1e30;
        }
        const double d = double(j - i0), v = double(steps[size_t(j)]) - double(steps[size_t(i0)]);
        lo = std::max(lo, (v - kTolerance) / d);
        hi = std::min(hi, (v + kTolerance) / d);
    }
    if (n > 1) keep(n - 1);
    if (int(steps.size()) > n) column.last = steps[size_t(n - 1)];
}

} // namespace volmorph::render
