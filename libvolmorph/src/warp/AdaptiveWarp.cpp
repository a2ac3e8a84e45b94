#include "AdaptiveWarp.h"

#include <openvdb/tools/Morphology.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <mutex>

namespace volmorph::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

/// A cell is locked when its measured error is at most this fraction of the tolerance: the error
/// is measured at the lattice points only, and in between it can be somewhat larger (the tests
/// measure every voxel against the exact warp).
constexpr double kSafety = 0.5;

/// A cell may be interpolated only when size <= kKappa * (d_min + epsilon) for every element.
constexpr double kKappa = 0.5;

/// Floor division by 8 (block coordinates), correct for negative coordinates.
inline int block(int v) { return v >= 0 ? v / 8 : -((-v + 7) / 8); }

inline Vec3d trilinear(const Vec3d c[8], double fx, double fy, double fz)
{
    const Vec3d x00 = c[0] + fx * (c[1] - c[0]), x10 = c[2] + fx * (c[3] - c[2]);
    const Vec3d x01 = c[4] + fx * (c[5] - c[4]), x11 = c[6] + fx * (c[7] - c[6]);
    const Vec3d y0 = x00 + fy * (x10 - x00), y1 = x01 + fy * (x11 - x01);
    return y0 + fz * (y1 - y0);
}

inline int latticeIndex(int a, int b, int c) { return a + 3 * b + 9 * c; }

/// Corner k (bit 0: x, bit 1: y, bit 2: z) as a lattice index.

} // namespace

// ------------------------------------------------------------------------------------------------

Occupancy::Occupancy(const openvdb::FloatTree& tree)
{
    openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(mBlocks);
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf)
        if (!leaf->isEmpty()) acc.setValueOn(Coord(block(leaf->origin().x()), block(leaf->origin().y()), block(leaf->origin().z())));
    auto tiles = tree.cbeginValueOn();
    tiles.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1); // tiles only, not voxels
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        const CoordBBox b = tiles.getBoundingBox();
        mBlocks.fill(CoordBBox(Coord(block(b.min().x()), block(b.min().y()), block(b.min().z())),
                               Coord(block(b.max().x()), block(b.max().y()), block(b.max().z()))),
                     true, true);
    }
    openvdb::tools::dilateActiveValues(mBlocks, 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::PRESERVE_TILES);
}

bool Occupancy::anyIn(const CoordBBox& box) const
{
    const Coord lo(block(box.min().x()), block(box.min().y()), block(box.min().z()));
    const Coord hi(block(box.max().x()), block(box.max().y()), block(box.max().z()));
    const CoordBBox blocks(lo, hi);
    if (blocks.volume() > (1u << 16)) return true; // too large to be worth asking
    openvdb::tree::ValueAccessor<const openvdb::MaskTree> acc(mBlocks);
    for (int x = lo.x(); x <= hi.x(); ++x)
        for (int y = lo.y(); y <= hi.y(); ++y)
            for (int z = lo.z(); z <= hi.z(); ++z)
                if (acc.isValueOn(Coord(x, y, z))) return true;
    return false;
}

CoordBBox Occupancy::bounds() const
{
    CoordBBox b;
    if (!mBlocks.evalActiveVoxelBoundingBox(b)) return CoordBBox();
    const Coord lo = b.min(), hi = b.max();
    return CoordBBox(Coord(lo.x() * 8, lo.y() * 8, lo.z() * 8), Coord(hi.x() * 8 + 7, hi.y() * 8 + 7, hi.z() * 8 + 7));
}

// ------------------------------------------------------------------------------------------------

struct AdaptiveWarp::Context {
    CoordBBox box;
    const Occupancy* source;
    const Occupancy* target;
    const LeafFunction* fn;
    const CellFilter* wanted;
    WarpLeaf leaf;
    double maxError = 0.0;
    uint64_t evaluations = 0, leaves = 0;

    struct Lattice {
        Vec3d s[27], t[27];
    };
};

AdaptiveWarp::AdaptiveWarp(const InverseWarp& warp, double toleranceVoxels, double epsilonVoxels)
    : mWarp(warp), mTolerance(toleranceVoxels), mEpsilon(epsilonVoxels)
{
}

bool AdaptiveWarp::nearElement(const Coord& origin, int size) const
{
    if (mWarp.pairCount() < 2) return false; // one pair: the warp is its affine map, exactly trilinear
    const double half = 0.5 * size;
    const Vec3d centre(origin.x() + half, origin.y() + half, origin.z() + half);
    const double reach = half * std::sqrt(3.0); // the distance is 1-Lipschitz: it changes by at most this
    for (size_t i = 0; i < mWarp.pairCount(); ++i) {
        const Feature& e = mWarp.interpolated(i);
        const double dMin = std::max(0.0, e.distance(centre) - reach);
        if (double(size) <= kKappa * (dMin + mEpsilon)) continue;
        if (e.type == FeatureType::Box) {
            // Wholly inside the box (convex: all corners inside), d = 0 and the weight is constant.
            bool inside = true;
            for (int k = 0; k < 8 && inside; ++k)
                inside = e.distance(Vec3d(origin.x() + (k & 1) * size, origin.y() + ((k >> 1) & 1) * size,
                                          origin.z() + ((k >> 2) & 1) * size)) == 0.0;
            if (inside) continue;
        }
        return true;
    }
    return false;
}

namespace {

/// The 27 points of a cell's next finer lattice: corners copied, the rest exact (or interpolated
/// when the cell is locked). Returns the measured error, in voxels (0 for a locked cell).
template <typename Map>
double evaluateLattice(const Map& map, const Coord& origin, int size, const Vec3d cs[8], const Vec3d ct[8],
                       bool locked, Vec3d ls[27], Vec3d lt[27], uint64_t& evaluations)
{
    double error = 0.0;
    const int half = size / 2;
    for (int c = 0; c < 3; ++c)
        for (int b = 0; b < 3; ++b)
            for (int a = 0; a < 3; ++a) {
                const int i = latticeIndex(a, b, c);
                if (!(a & 1) && !(b & 1) && !(c & 1)) {
                    const int k = (a >> 1) | ((b >> 1) << 1) | ((c >> 1) << 2);
                    ls[i] = cs[k];
                    lt[i] = ct[k];
                    continue;
                }
                const Vec3d is = trilinear(cs, 0.5 * a, 0.5 * b, 0.5 * c);
                const Vec3d it = trilinear(ct, 0.5 * a, 0.5 * b, 0.5 * c);
                if (locked) {
                    ls[i] = is;
                    lt[i] = it;
                    continue;
                }
                map(Vec3d(origin.x() + a * half, origin.y() + b * half, origin.z() + c * half), ls[i], lt[i]);
                ++evaluations;
                error = std::max({error, (ls[i] - is).length(), (lt[i] - it).length()});
            }
    return error;
}

void childCorners(const Vec3d ls[27], const Vec3d lt[27], int cx, int cy, int cz, Vec3d cs[8], Vec3d ct[8])
{
    for (int k = 0; k < 8; ++k) {
        const int i = latticeIndex(cx + (k & 1), cy + ((k >> 1) & 1), cz + ((k >> 2) & 1));
        cs[k] = ls[i];
        ct[k] = lt[i];
    }
}

CoordBBox imageBox(const Vec3d points[27], double margin)
{
    Vec3d lo = points[0], hi = points[0];
    for (int i = 1; i < 27; ++i) {
        lo = minComponent(lo, points[i]);
        hi = maxComponent(hi, points[i]);
    }
    auto clampInt = [](double v) { return int(std::clamp(v, -1.0e9, 1.0e9)); };
    return CoordBBox(Coord(clampInt(std::floor(lo.x() - margin)), clampInt(std::floor(lo.y() - margin)),
                           clampInt(std::floor(lo.z() - margin))),
                     Coord(clampInt(std::ceil(hi.x() + margin)), clampInt(std::ceil(hi.y() + margin)),
                           clampInt(std::ceil(hi.z() + margin))));
}

} // namespace

void AdaptiveWarp::cell(Context& ctx, const Coord& origin, int size, const Corners& corners, bool locked) const
{
    const CoordBBox cube = CoordBBox::createCube(origin, size);
    if (!ctx.box.hasOverlap(cube) || (ctx.wanted && !(*ctx.wanted)(cube))) return;
    auto map = [this](const Vec3d& p, Vec3d& s, Vec3d& t) { mWarp.map(p, s, t); };
    Context::Lattice l;
    const double error = evaluateLattice(map, origin, size, corners.s, corners.t, locked, l.s, l.t, ctx.evaluations);

    if ((ctx.source || ctx.target) && error <= double(size)) {
        // Trilinear sampling reads up to one voxel past the point; interpolated points stay within
        // their corners' hull, exact ones may stray from it by about the measured error.
        const double margin = 1.5 + 2.0 * error;
        const bool keep = (ctx.source && ctx.source->anyIn(imageBox(l.s, margin))) ||
                          (ctx.target && ctx.target->anyIn(imageBox(l.t, margin)));
        if (!keep) return;
    }
    const bool lock = locked || (mTolerance > 0.0 && error <= kSafety * mTolerance && !nearElement(origin, size));
    if (lock && !locked) ctx.maxError = std::max(ctx.maxError, error);

    if (size > 8) {
        const int half = size / 2;
        Corners child;
        for (int cz = 0; cz < 2; ++cz)
            for (int cy = 0; cy < 2; ++cy)
                for (int cx = 0; cx < 2; ++cx) {
                    childCorners(l.s, l.t, cx, cy, cz, child.s, child.t);
                    cell(ctx, origin.offsetBy(cx * half, cy * half, cz * half), half, child, lock);
                }
        return;
    }
    ctx.leaf.origin = origin;
    ++ctx.leaves;
    if (mWarp.pairCount() == 0) {
        fillIdentity(ctx, origin);
    } else if (mTolerance == 0.0) {
        exactBlock(ctx, origin, 8);
    } else if (lock) {
        fillTrilinear(ctx, origin, 8, corners);
    } else {
        // The leaf's lattice is already known: its 8 children of 4^3 take their corners from it.
        Corners child;
        for (int cz = 0; cz < 2; ++cz)
            for (int cy = 0; cy < 2; ++cy)
                for (int cx = 0; cx < 2; ++cx) {
                    childCorners(l.s, l.t, cx, cy, cz, child.s, child.t);
                    quarter(ctx, origin.offsetBy(cx * 4, cy * 4, cz * 4), child);
                }
    }
    (*ctx.fn)(ctx.leaf);
}

void AdaptiveWarp::exactBlock(Context& ctx, const Coord& origin, int size) const
{
    const Coord local = origin - ctx.leaf.origin;
    Vec3d s, t;
    for (int i = 0; i < size; ++i)
        for (int j = 0; j < size; ++j)
            for (int k = 0; k < size; ++k) {
                mWarp.map(Vec3d(origin.x() + i, origin.y() + j, origin.z() + k), s, t);
                const int n = ((local.x() + i) * 8 + local.y() + j) * 8 + local.z() + k;
                ctx.leaf.source[n] = Vec3f(s);
                ctx.leaf.target[n] = Vec3f(t);
            }
    ctx.evaluations += uint64_t(size) * size * size;
}

void AdaptiveWarp::fillIdentity(Context& ctx, const Coord& origin) const
{
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                const Vec3f p(float(origin.x() + i), float(origin.y() + j), float(origin.z() + k));
                ctx.leaf.source[(i * 8 + j) * 8 + k] = p;
                ctx.leaf.target[(i * 8 + j) * 8 + k] = p;
            }
}

void AdaptiveWarp::fillTrilinear(Context& ctx, const Coord& origin, int size, const Corners& corners) const
{
    const Coord local = origin - ctx.leaf.origin;
    const double step = 1.0 / double(size);
    for (int i = 0; i < size; ++i)
        for (int j = 0; j < size; ++j)
            for (int k = 0; k < size; ++k) {
                const int n = ((local.x() + i) * 8 + local.y() + j) * 8 + local.z() + k;
                ctx.leaf.source[n] = Vec3f(trilinear(corners.s, i * step, j * step, k * step));
                ctx.leaf.target[n] = Vec3f(trilinear(corners.t, i * step, j * step, k * step));
            }
}

void AdaptiveWarp::quarter(Context& ctx, const Coord& origin, const Corners& corners) const
{
    // A 4^3 cell: interpolated when its lattice check passes, else exact voxel by voxel (64
    // evaluations, fewer than the 8 x 19 that splitting it into 2^3 cells would cost).
    if (nearElement(origin, 4)) {
        exactBlock(ctx, origin, 4);
        return;
    }
    auto map = [this](const Vec3d& p, Vec3d& s, Vec3d& t) { mWarp.map(p, s, t); };
    Context::Lattice l;
    const double error = evaluateLattice(map, origin, 4, corners.s, corners.t, false, l.s, l.t, ctx.evaluations);
    if (error <= kSafety * mTolerance) {
        ctx.maxError = std::max(ctx.maxError, error);
        fillTrilinear(ctx, origin, 4, corners);
    } else {
        exactBlock(ctx, origin, 4);
    }
}

void AdaptiveWarp::forEachLeaf(const CoordBBox& box, const Occupancy* source, const Occupancy* target,
                               const LeafFunction& fn, AdaptiveWarpStats* stats, Interrupter* interrupter,
                               const CellFilter* wanted) const
{
    if (box.empty()) return;
    auto down = [](int v) { return v >= 0 ? v / kTopCell * kTopCell : -((-v + kTopCell - 1) / kTopCell) * kTopCell; };
    const Coord lo(down(box.min().x()), down(box.min().y()), down(box.min().z()));
    std::vector<Coord> tops;
    for (int x = lo.x(); x <= box.max().x(); x += kTopCell)
        for (int y = lo.y(); y <= box.max().y(); y += kTopCell)
            for (int z = lo.z(); z <= box.max().z(); z += kTopCell) tops.emplace_back(x, y, z);

    std::mutex statsMutex;
    std::atomic<bool> stopped{false};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tops.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
        auto ctx = std::make_unique<Context>();
        ctx->box = box;
        ctx->source = source;
        ctx->target = target;
        ctx->fn = &fn;
        ctx->wanted = wanted;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            if (stopped || (interrupter && interrupter->wasInterrupted(int(100 * i / tops.size())))) {
                stopped = true;
                return;
            }
            Corners corners;
            for (int k = 0; k < 8; ++k) {
                const Coord c = tops[i].offsetBy((k & 1) * kTopCell, ((k >> 1) & 1) * kTopCell, ((k >> 2) & 1) * kTopCell);
                mWarp.map(c.asVec3d(), corners.s[k], corners.t[k]);
            }
            ctx->evaluations += 8;
            cell(*ctx, tops[i], kTopCell, corners, false);
        }
        if (stats) {
            std::lock_guard<std::mutex> lock(statsMutex);
            stats->maxErrorVoxels = std::max(stats->maxErrorVoxels, ctx->maxError);
            stats->exactEvaluations += ctx->evaluations;
            stats->leaves += ctx->leaves;
        }
    });
    if (stopped) throw Interrupted();
}

} // namespace volmorph::detail
