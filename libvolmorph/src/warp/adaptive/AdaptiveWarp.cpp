// The approximated warp's traversal (AdaptiveWarp.h): the candidate cells, the lattice's exact
// sums, and each leaf analysed (ErrorBound), culled (DomainTest), filled (LeafKernel), handed on.
#include "warp/AdaptiveWarp.h"

#include "warp/adaptive/Context.h"
#include "warp/adaptive/DomainTest.h"
#include "warp/adaptive/PairColumns.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;

AdaptiveWarp::~AdaptiveWarp() = default;

AdaptiveWarp::AdaptiveWarp(const InverseWarp& warp, double toleranceVoxels, KernelBuild limit)
    : mWarp(warp), mTolerance(toleranceVoxels),
      mBuild(KernelBuild(std::min(int(bestKernelBuild()), int(limit))))
{
    const size_t n = warp.pairCount();
    for (size_t i = 0; i < n; ++i) {
        mSource.push_back(warp.sourceAffine(i));
        mTarget.push_back(warp.targetAffine(i));
    }
    const std::vector<InverseWarp::Affine> maps[2] = {mSource, mTarget};
    mColumns = std::make_unique<const WarpColumns>(warp, maps);
    // The kernel's order of near pairs: by type, then by index.
    for (size_t i = 0; i < n; ++i) mByType.push_back(i);
    std::stable_sort(mByType.begin(), mByType.end(), [&warp](size_t a, size_t b) {
        return warp.interpolated(a).type < warp.interpolated(b).type;
    });
}

void AdaptiveWarp::identityLeaf(WarpContext& ctx) const
{
    const Coord& o = ctx.leaf.origin;
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                const Vec3f p(float(o.x() + i), float(o.y() + j), float(o.z() + k));
                ctx.leaf.set((i * 8 + j) * 8 + k, p, p);
            }
}

void AdaptiveWarp::exactLeaf(WarpContext& ctx) const
{
    const Coord& o = ctx.leaf.origin;
    Vec3d s, t;
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                mWarp.map(Vec3d(o.x() + i, o.y() + j, o.z() + k), s, t);
                ctx.leaf.set((i * 8 + j) * 8 + k, Vec3f(s), Vec3f(t));
            }
    ctx.evaluations += 512;
}

void AdaptiveWarp::fill(WarpContext& ctx, const Coord& origin) const
{
    const Vec3d o = origin.asVec3d();
    const InverseWarp::Affine& bS = mSource[ctx.dominant];
    const InverseWarp::Affine& bT = mTarget[ctx.dominant];

    // The exact sums at the corners, as W, S - W B and T - W B (B at the corners from analyze());
    // the kernel takes the near pairs off them (G = N - W B - sum_E w_i R_i, W_F = W - sum_E w_i).
    LeafJob& job = *ctx.job;
    for (int c = 0; c < 8; ++c) {
        const LatticePoint& p = *ctx.corner[c];
        job.far[0][c] = p.w;
        for (int k = 0; k < 3; ++k) {
            job.far[1 + k][c] = p.s[k] - p.w * ctx.cornerB[0][k][c];
            job.far[4 + k][c] = p.t[k] - p.w * ctx.cornerB[1][k][c];
        }
    }
    job.origin = o;
    job.bS = bS;
    job.bT = bT;
    job.offset = mWarp.weightOffset();
    job.exponent = mWarp.weightExponent();
    job.inverseSquare = mWarp.weighting() == Weighting::InverseSquare;
    job.near.clear();
    const Vec3d bso = bS.apply(o), bto = bT.apply(o);
    for (int type = 0; type < 4; ++type) job.typeEnd[type] = 0;
    for (const size_t p : ctx.nearList) { // by type, then by index
        NearTerm t;
        t.element = &mWarp.interpolated(p);
        t.scale = mWarp.weightScale(p);
        for (int k = 0; k < 3; ++k)
            t.half[k] = mColumns->exact.get(PairColumns<double>::Half + k, p);
        t.rs = mSource[p].apply(o) - bso;
        t.rt = mTarget[p].apply(o) - bto;
        for (int k = 0; k < 3; ++k) {
            t.drs[k] = mSource[p].col[k] - bS.col[k];
            t.drt[k] = mTarget[p].col[k] - bT.col[k];
        }
        job.near.push_back(t);
        ++job.typeEnd[int(mWarp.interpolated(p).type)];
    }
    for (int type = 1; type < 4; ++type)
        job.typeEnd[type] += job.typeEnd[type - 1]; // counts to ends
    fillLeaf(job, ctx.leaf, mBuild);
}

void AdaptiveWarp::leaf(WarpContext& ctx, const Lattice& lattice, const Coord& origin) const
{
    ctx.leaf.origin = origin;
    const bool cull = ctx.source || ctx.target;
    const size_t n = mWarp.pairCount();
    const Vec3d o = origin.asVec3d();
    // `recheck`: cull again by the filled points, when only the bound's margin kept the leaf.
    auto visit = [&](double errorBound, bool recheck) {
        if (cull && recheck) {
            // The filled points' own bounding box, widened by what they may be off.
            Vec3f lo[2], hi[2];
            leafRange(ctx.leaf, lo, hi, mBuild);
            const double margin = kSamplerReach + errorBound;
            if (!touches(ctx.source, Vec3d(lo[0]), Vec3d(hi[0]), margin) &&
                !touches(ctx.target, Vec3d(lo[1]), Vec3d(hi[1]), margin))
                return;
        }
        ++ctx.leaves;
        ctx.leaf.errorBound = errorBound;
        (*ctx.fn)(ctx.leaf);
    };

    if (n == 0) {
        if (cull && !touches(ctx.source, o, o + Vec3d(7.0), kSamplerReach) &&
            !touches(ctx.target, o, o + Vec3d(7.0), kSamplerReach))
            return;
        identityLeaf(ctx);
        ctx.leaf.errorBound = 0.0;
        ++ctx.leaves;
        (*ctx.fn)(ctx.leaf);
        return;
    }

    const Coord lc(origin.x() >> 3, origin.y() >> 3, origin.z() >> 3);
    const LatticePoint* corners[8];
    for (int k = 0; k < 8; ++k)
        corners[k] = &lattice.points[lattice.index(lc.offsetBy(k & 1, (k >> 1) & 1, (k >> 2) & 1))];
    analyze(ctx, corners, origin, 8);
    if (cull && !mayTouch(ctx, origin, 8)) return;
    if (mTolerance <= 0.0 || !ctx.cornersOk || ctx.tiny) {
        exactLeaf(ctx);
        visit(0.0, !ctx.coreTouches);
        return;
    }

    size_t nearCount = 0;
    const double bound = selectNear(ctx, nearCount);
    const uint64_t near = uint64_t(nearCount) * 512;
    fill(ctx, origin);
    ctx.near += near;
    ctx.allFar += nearCount == 0;
    ctx.maxError = std::max(ctx.maxError, bound);
    visit(bound, !ctx.coreTouches);
}

namespace {

/// v rounded down to a multiple of `size`.
int floorTo(int v, int size)
{
    return v >= 0 ? v / size * size : -((-v + size - 1) / size) * size;
}

/// A cell of 2^3 leaves (16 voxels) and the mask of its leaves to visit.
struct Cell {
    Coord origin;
    uint8_t leaves; ///< bit (x << 2 | y << 1 | z): the leaf at origin + 8 (x, y, z)
};

} // namespace

/// One forEachLeaf call: its steps and what they share.
class AdaptiveWarp::Traversal {
public:
    Traversal(const AdaptiveWarp& warp, const CoordBBox& box, const Occupancy* source,
              const Occupancy* target, const LeafFunction& fn, Interrupter* interrupter,
              const CellFilter* wanted)
        : w(warp), mBox(box), mSource(source), mTarget(target), mInterrupter(interrupter),
          mWanted(wanted), mContexts([source, target, &fn] {
              WarpContext ctx;
              ctx.source = source;
              ctx.target = target;
              ctx.fn = &fn;
              return ctx;
          })
    {
    }

    /// 1. Candidate cells of 2^3 leaves, each with the mask of its leaves that lie in the box and
    ///    are wanted, gathered per top cell: top cells the filter refuses, or whose image under
    ///    every pair's affine map misses both sides' occupied blocks, are skipped whole. False
    ///    when there are none.
    bool findCells()
    {
        const Coord lo(floorTo(mBox.min().x(), kTopCell), floorTo(mBox.min().y(), kTopCell),
                       floorTo(mBox.min().z(), kTopCell));
        std::vector<Coord> tops;
        for (int x = lo.x(); x <= mBox.max().x(); x += kTopCell)
            for (int y = lo.y(); y <= mBox.max().y(); y += kTopCell)
                for (int z = lo.z(); z <= mBox.max().z(); z += kTopCell) tops.emplace_back(x, y, z);
        std::vector<std::vector<Cell>> perTop(tops.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tops.size(), 1),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t ti = r.begin(); ti != r.end(); ++ti)
                                  perTop[ti] = cellsOf(CoordBBox::createCube(tops[ti], kTopCell));
                          });
        for (const auto& v : perTop) mCells.insert(mCells.end(), v.begin(), v.end());
        return !mCells.empty();
    }

    /// 1'. Instead of findCells(): the cells of a given list of leaves. False when it is empty.
    bool listCells(const std::vector<Coord>& leaves)
    {
        std::map<Coord, uint8_t> cells;
        for (const Coord& c : leaves) {
            const Coord cell(c.x() & -16, c.y() & -16, c.z() & -16);
            const int m = ((c.x() >> 3) & 1) << 2 | ((c.y() >> 3) & 1) << 1 | ((c.z() >> 3) & 1);
            cells[cell] |= uint8_t(1u << m);
        }
        for (const auto& [origin, mask] : cells) mCells.push_back(Cell{origin, mask});
        return !mCells.empty();
    }

    /// 2. The exact sums at the corners of the candidate leaves, each lattice point once. With
    ///    occupancies, blocks of 2^3 cells and then cells are culled first from their own corners
    ///    (every 4th, then every other lattice point), so that the leaves of a cell whose image
    ///    misses both sides cost nothing.
    void evaluateLattice()
    {
        if (w.mWarp.pairCount() == 0) return expand();
        allocateLattice();
        if (mSource || mTarget) {
            cull(32);
            cull(16);
        }
        expand();
        // The candidates' corners, found in parallel, listed in the threads' order (the points do
        // not depend on the order they are evaluated in).
        tbb::enumerable_thread_specific<std::vector<size_t>> found;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, mCandidates.size(), 512),
                          [&](const tbb::blocked_range<size_t>& r) {
                              std::vector<size_t>& list = found.local();
                              for (size_t i = r.begin(); i != r.end(); ++i)
                                  want(mCandidates[i], 1, list);
                          });
        for (const std::vector<size_t>& list : found)
            mPending.insert(mPending.end(), list.begin(), list.end());
        evaluate(5);
    }

    /// 3. Every candidate leaf: culled by the bound, filled, culled by its points, handed on.
    void visitLeaves()
    {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, mCandidates.size(), 16),
                          [&](const tbb::blocked_range<size_t>& r) {
                              if (stop(10 + int(90 * r.begin() / mCandidates.size()))) return;
                              WarpContext& ctx = mContexts.local();
                              for (size_t i = r.begin(); i != r.end(); ++i)
                                  w.leaf(ctx, mLattice, mCandidates[i]);
                          });
        if (mStopped) throw Interrupted();
    }

    /// The threads' counters, summed.
    void addStats(AdaptiveWarpStats& stats) const
    {
        for (const WarpContext& ctx : mContexts) {
            stats.maxErrorVoxels = std::max(stats.maxErrorVoxels, ctx.maxError);
            stats.exactEvaluations += ctx.evaluations;
            stats.nearEvaluations += ctx.near;
            stats.allFarLeaves += ctx.allFar;
            stats.leaves += ctx.leaves;
        }
        stats.exactEvaluations += mLatticeEvaluations;
    }

private:
    /// The candidate cells of one top cell, in the order of their blocks of 2^3 cells (step 2
    /// culls blocks, then cells).
    std::vector<Cell> cellsOf(const CoordBBox& cube) const
    {
        std::vector<Cell> out;
        if (mWanted && !(*mWanted)(cube)) return out;
        if ((mSource || mTarget) && w.mWarp.pairCount() > 0 &&
            !hullMayTouch(cube, w.mSource, w.mTarget, mSource, mTarget))
            return out;
        CoordBBox part = cube;
        part.intersect(mBox);
        if (part.empty()) return out;
        const CoordBBox leafRange(Coord(floorTo(part.min().x(), 8), floorTo(part.min().y(), 8),
                                        floorTo(part.min().z(), 8)),
                                  part.max()); // the leaves' origins
        const CoordBBox cellRange(Coord(floorTo(part.min().x(), 16), floorTo(part.min().y(), 16),
                                        floorTo(part.min().z(), 16)),
                                  part.max());
        for (int bx = floorTo(part.min().x(), 32); bx <= part.max().x(); bx += 32)
            for (int by = floorTo(part.min().y(), 32); by <= part.max().y(); by += 32)
                for (int bz = floorTo(part.min().z(), 32); bz <= part.max().z(); bz += 32)
                    for (int k = 0; k < 8; ++k) {
                        const Coord o(bx + ((k >> 2) & 1) * 16, by + ((k >> 1) & 1) * 16,
                                      bz + (k & 1) * 16);
                        if (!cellRange.isInside(o)) continue;
                        const Cell cell{o, leavesOf(o, leafRange)};
                        if (cell.leaves) out.push_back(cell);
                    }
        return out;
    }

    /// The mask of the cell's leaves that lie in `leafRange` and are wanted.
    uint8_t leavesOf(const Coord& cell, const CoordBBox& leafRange) const
    {
        uint8_t leaves = 0;
        for (int m = 0; m < 8; ++m) {
            const Coord c = cell.offsetBy(((m >> 2) & 1) * 8, ((m >> 1) & 1) * 8, (m & 1) * 8);
            if (!leafRange.isInside(c)) continue;
            if (mWanted && !(*mWanted)(CoordBBox::createCube(c, 8))) continue;
            leaves |= uint8_t(1u << m);
        }
        return leaves;
    }

    /// The lattice over the cells' leaves, and the corners of their blocks of 32 voxels too;
    /// left uninitialized (LatticePoint).
    void allocateLattice()
    {
        Coord llo(std::numeric_limits<int>::max()), lhi(std::numeric_limits<int>::min());
        for (const Cell& c : mCells) {
            const Coord l(c.origin.x() >> 3 & -4, c.origin.y() >> 3 & -4, c.origin.z() >> 3 & -4);
            llo = Coord::minComponent(llo, l);
            lhi = Coord::maxComponent(lhi, l.offsetBy(4));
        }
        mLattice.lo = llo;
        mLattice.dim = lhi - llo + Coord(1);
        mLattice.count = size_t(mLattice.dim.x()) * mLattice.dim.y() * mLattice.dim.z();
        mLattice.points.reset(new LatticePoint[mLattice.count]);
        mClaimed.assign(mLattice.count, 0);
    }

    /// Wants the corners of the cube of `step` lattice cells at origin; new ones go to `list`.
    /// Safe from several threads at once (each point is claimed by one atomic exchange). Each
    /// point is listed once, when first wanted, and evaluated by the next evaluate() (the lists
    /// are not scanned for: the lattice's box is mostly unwanted).
    void want(const Coord& origin, int step, std::vector<size_t>& list)
    {
        const Coord l(origin.x() >> 3, origin.y() >> 3, origin.z() >> 3);
        for (int k = 0; k < 8; ++k) {
            const size_t i = mLattice.index(
                l.offsetBy((k & 1) * step, ((k >> 1) & 1) * step, ((k >> 2) & 1) * step));
            if (!mClaimed[i] && __atomic_exchange_n(&mClaimed[i], char(1), __ATOMIC_RELAXED) == 0)
                list.push_back(i);
        }
    }

    /// Evaluates the pending lattice points (progress from `progressFrom` percent, 5 more).
    void evaluate(int progressFrom)
    {
        std::vector<size_t> todo;
        todo.swap(mPending);
        mLatticeEvaluations += todo.size();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, todo.size(), 64),
                          [&](const tbb::blocked_range<size_t>& r) {
                              if (stop(progressFrom + int(5 * r.begin() / todo.size()))) return;
                              const int yz = mLattice.dim.y() * mLattice.dim.z();
                              for (size_t i = r.begin(); i != r.end(); ++i) {
                                  const size_t idx = todo[i];
                                  const Coord l(mLattice.lo.x() + int(idx / yz),
                                                mLattice.lo.y() + int(idx % yz) / mLattice.dim.z(),
                                                mLattice.lo.z() + int(idx % mLattice.dim.z()));
                                  LatticePoint& p = mLattice.points[idx];
                                  p.ok =
                                      w.exactSums(Vec3d(l.x() * 8.0, l.y() * 8.0, l.z() * 8.0), p);
                              }
                          });
        if (mStopped) throw Interrupted();
    }

    /// Keeps the groups of cells (blocks of `size` voxels, 32 or 16) whose image may come near
    /// an occupied block, judged from the group's own corners.
    void cull(int size)
    {
        auto groupOf = [size](const Coord& c) {
            return Coord(c.x() & -size, c.y() & -size, c.z() & -size);
        };
        std::vector<size_t> begin; // where each group's cells begin
        for (size_t i = 0; i < mCells.size(); ++i)
            if (i == 0 || groupOf(mCells[i].origin) != groupOf(mCells[i - 1].origin))
                begin.push_back(i);
        begin.push_back(mCells.size());
        const int step = size / 8;
        for (size_t g = 0; g + 1 < begin.size(); ++g)
            want(groupOf(mCells[begin[g]].origin), step, mPending);
        evaluate(0);
        std::vector<char> keep(begin.size() - 1, 0);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, keep.size(), 8),
                          [&](const tbb::blocked_range<size_t>& r) {
                              WarpContext& ctx = mContexts.local();
                              for (size_t g = r.begin(); g != r.end(); ++g)
                                  keep[g] =
                                      groupMayTouch(ctx, groupOf(mCells[begin[g]].origin), size);
                          });
        size_t kept = 0;
        for (size_t g = 0; g < keep.size(); ++g)
            if (keep[g])
                for (size_t c = begin[g]; c < begin[g + 1]; ++c) mCells[kept++] = mCells[c];
        mCells.resize(kept);
    }

    /// The domain test of the cube of `size` voxels at o, from the lattice points at its corners.
    bool groupMayTouch(WarpContext& ctx, const Coord& o, int size) const
    {
        const int step = size / 8;
        const Coord l(o.x() >> 3, o.y() >> 3, o.z() >> 3);
        const LatticePoint* corners[8];
        for (int k = 0; k < 8; ++k)
            corners[k] = &mLattice.points[mLattice.index(
                l.offsetBy((k & 1) * step, ((k >> 1) & 1) * step, ((k >> 2) & 1) * step))];
        w.analyze(ctx, corners, o, size);
        return w.mayTouch(ctx, o, size);
    }

    /// The candidate leaves, cell by cell.
    void expand()
    {
        for (const Cell& cell : mCells)
            for (int k = 0; k < 8; ++k)
                if (cell.leaves & (1u << k))
                    mCandidates.push_back(
                        cell.origin.offsetBy(((k >> 2) & 1) * 8, ((k >> 1) & 1) * 8, (k & 1) * 8));
    }

    /// True (and remembered) once the interrupter asks to stop.
    bool stop(int percent)
    {
        if (mStopped || (mInterrupter && mInterrupter->wasInterrupted(percent))) mStopped = true;
        return mStopped;
    }

    const AdaptiveWarp& w;
    const CoordBBox mBox;
    const Occupancy* mSource;
    const Occupancy* mTarget;
    Interrupter* mInterrupter;
    const CellFilter* mWanted;
    std::vector<Cell> mCells;
    std::vector<Coord> mCandidates;
    Lattice mLattice;
    std::vector<char> mClaimed; ///< per lattice point: listed for evaluation already
    std::vector<size_t> mPending;
    uint64_t mLatticeEvaluations = 0;
    std::atomic<bool> mStopped{false};
    /// One scratch context per thread (its counters summed into the stats at the end).
    tbb::enumerable_thread_specific<WarpContext> mContexts;
};

void AdaptiveWarp::fillLeaves(const std::vector<Coord>& leaves, const LeafFunction& fn,
                              AdaptiveWarpStats* stats, Interrupter* interrupter) const
{
    Traversal traversal(*this, CoordBBox(), nullptr, nullptr, fn, interrupter, nullptr);
    if (!traversal.listCells(leaves)) return;
    traversal.evaluateLattice();
    traversal.visitLeaves();
    if (stats) traversal.addStats(*stats);
}

void AdaptiveWarp::forEachLeaf(const CoordBBox& box, const Occupancy* source,
                               const Occupancy* target, const LeafFunction& fn,
                               AdaptiveWarpStats* stats, Interrupter* interrupter,
                               const CellFilter* wanted) const
{
    if (box.empty()) return;
    Traversal traversal(*this, box, source, target, fn, interrupter, wanted);
    if (!traversal.findCells()) return;
    if (interrupter && interrupter->wasInterrupted(0)) throw Interrupted();
    traversal.evaluateLattice();
    traversal.visitLeaves();
    if (stats) traversal.addStats(*stats);
}

} // namespace volmorph::detail
