// The warp under a timing (TimedWarp.h): the table of levels, the map and its velocity at points,
// and the leaves filled level by level and blended.
#include "warp/TimedWarp.h"

#include "warp/adaptive/DomainTest.h"
#include "warp/adaptive/LeafKernel.h"

#include <volmorph/core/Interrupter.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;

namespace {

/// The points of `region`'s lattice, some 12 along its longest side (8 voxels apart at least).
std::vector<Vec3d> latticePoints(const CoordBBox& region)
{
    std::vector<Vec3d> out;
    if (region.empty()) return out;
    const Coord dim = region.dim();
    const int step = std::max(8, (std::max({dim.x(), dim.y(), dim.z()}) + 11) / 12);
    for (int x = region.min().x(); x <= region.max().x() + step - 1; x += step)
        for (int y = region.min().y(); y <= region.max().y() + step - 1; y += step)
            for (int z = region.min().z(); z <= region.max().z() + step - 1; z += step)
                out.emplace_back(std::min(x, region.max().x()), std::min(y, region.max().y()),
                                 std::min(z, region.max().z()));
    return out;
}

/// Where the warp changes fastest with tau: on and about each interpolated element of `warp` (its
/// centre and its extent's corners, and each of those moved by twice the weights' offset, at
/// least a voxel, along every axis).
void addElementPoints(const InverseWarp& warp, std::vector<Vec3d>& out)
{
    const double r = std::max(1.0, 2.0 * warp.weightOffset());
    for (size_t i = 0; i < warp.pairCount(); ++i) {
        const Feature& e = warp.interpolated(i);
        const int axes = e.extendedAxes();
        for (int c = 0; c < (1 << axes) + 1; ++c) {
            Vec3d u(0.0); // the centre, then the corners of the extent
            if (c > 0)
                for (int k = 0; k < axes; ++k) u[k] = ((c - 1) >> k & 1) ? 0.5 : -0.5;
            const Vec3d q = e.fromLocal(u);
            out.push_back(q);
            for (int k = 0; k < 6; ++k) {
                Vec3d step(0.0);
                step[k / 2] = k % 2 ? r : -r;
                out.push_back(q + step);
            }
        }
    }
}

/// Halves [a, b] until its midpoint's map is within `tolerance` of its ends' blend at the
/// lattice's points and about the elements at a, at the midpoint and at b; appends the levels
/// after a, up to b.
struct Bisection {
    const std::vector<FeaturePairSpec>& pairs;
    const WarpSpec& spec;
    double unit, tolerance;
    const std::vector<Vec3d>& lattice;
    TauTable& table;
    static constexpr int kMaxDepth = 2; ///< intervals of at least 1 / 64

    void run(double a, double b, int depth)
    {
        const double m = 0.5 * (a + b);
        const InverseWarp wa(pairs, spec, a, unit), wm(pairs, spec, m, unit),
            wb(pairs, spec, b, unit);
        std::vector<Vec3d> points = lattice;
        for (const InverseWarp* w : {&wa, &wm, &wb}) addElementPoints(*w, points);
        std::vector<double> deviation(points.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 64),
                          [&](const tbb::blocked_range<size_t>& r) {
                              Vec3d s[3], t[3];
                              for (size_t i = r.begin(); i != r.end(); ++i) {
                                  wa.map(points[i], s[0], t[0]);
                                  wm.map(points[i], s[1], t[1]);
                                  wb.map(points[i], s[2], t[2]);
                                  deviation[i] = std::max((s[1] - 0.5 * (s[0] + s[2])).length(),
                                                          (t[1] - 0.5 * (t[0] + t[2])).length());
                              }
                          });
        const double most = *std::max_element(deviation.begin(), deviation.end());
        if (most > tolerance && depth < kMaxDepth) {
            run(a, m, depth + 1);
            run(m, b, depth + 1);
            return;
        }
        table.levels.push_back(b);
        table.error = std::max(table.error, most);
    }
};

} // namespace

TauTable TauTable::make(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec,
                        double unit, const CoordBBox& region, double toleranceVoxels)
{
    TauTable table;
    table.levels = {0.0};
    const std::vector<Vec3d> lattice = latticePoints(region);
    Bisection halve{pairs,   spec, unit, 0.25 * (toleranceVoxels > 0.0 ? toleranceVoxels : 0.25),
                    lattice, table};
    constexpr int kFirst = 16;
    for (int i = 0; i < kFirst; ++i) halve.run(double(i) / kFirst, double(i + 1) / kFirst, 0);
    return table;
}

size_t TauTable::interval(double tau, double& f) const
{
    const auto above = std::upper_bound(levels.begin() + 1, levels.end() - 1, tau);
    const size_t k = size_t(above - levels.begin()) - 1;
    f = std::clamp((tau - levels[k]) / (levels[k + 1] - levels[k]), 0.0, 1.0);
    return k;
}

TimedWarp::TimedWarp(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec, double unit,
                     const TauTable& table, const LocalTime& local,
                     const openvdb::math::Transform& xform, double t, double toleranceVoxels)
    : mPairs(pairs), mSpec(spec), mUnit(unit), mTable(table), mLocal(local), mXform(xform), mT(t),
      mTolerance(toleranceVoxels), mVoxel(xform.voxelSize()[0])
{
    for (const double tau : table.levels) {
        mWarps.push_back(std::make_shared<const InverseWarp>(pairs, spec, tau, unit));
        // The table's estimate takes a quarter of the tolerance (TauTable::make).
        std::vector<InverseWarp::Affine> source, target;
        for (size_t i = 0; i < pairs.size(); ++i) {
            source.push_back(mWarps.back()->sourceAffine(i));
            target.push_back(mWarps.back()->targetAffine(i));
        }
        mAffines.emplace_back(std::move(source), std::move(target));
        if (mTolerance > 0.0) {
            mAdaptive.push_back(std::make_unique<AdaptiveWarp>(*mWarps.back(), 0.75 * mTolerance));
            mKernels.push_back(
                std::make_unique<VelocityKernel>(*mWarps.back(), VelocityLeaf::kExactWithin));
        }
    }
}

TimedWarp::~TimedWarp() = default;

LocalTau TimedWarp::tauAt(const Vec3d& p) const
{
    LocalTau out = mLocal.at(mXform.indexToWorld(p), mT);
    out.gradient *= mVoxel;
    return out;
}

std::shared_ptr<const InverseWarp> TimedWarp::warpAt(double tau) const
{
    double f;
    const size_t k = mTable.interval(tau, f);
    if (mTable.levels[k] == tau) return mWarps[k];
    if (mTable.levels[k + 1] == tau) return mWarps[k + 1];
    return std::make_shared<const InverseWarp>(mPairs, mSpec, tau, mUnit);
}

void TimedWarp::map(const Vec3d& p, Vec3d& source, Vec3d& target) const
{
    const double tau = tauAt(p).tau;
    if (mTolerance <= 0.0) return warpAt(tau)->map(p, source, target);
    double f;
    const size_t k = mTable.interval(tau, f);
    mWarps[k]->map(p, source, target);
    if (f == 0.0) return;
    Vec3d s, t;
    mWarps[k + 1]->map(p, s, t);
    source = (1.0 - f) * source + f * s;
    target = (1.0 - f) * target + f * t;
}

namespace {

/// The matrix a g^T.
openvdb::math::Mat3d outer(const Vec3d& a, const Vec3d& g)
{
    openvdb::math::Mat3d m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m(i, j) = a[i] * g[j];
    return m;
}

} // namespace

bool TimedWarp::exactVelocity(const Vec3d& p, Vec3d& source, Vec3d& target) const
{
    const LocalTau local = tauAt(p);
    source = target = Vec3d(0.0);
    if (local.dt == 0.0) return true; // tau clamped: the place does not move
    InverseWarp::Derivatives d[2];
    warpAt(local.tau)->derivatives(p, d[0], d[1]);
    for (InverseWarp::Derivatives& side : d) { // J + W_tau (grad tau)^T and W_tau tau_t
        side.jacobian += outer(side.rate, local.gradient);
        side.rate *= local.dt;
    }
    const bool a = InverseWarp::velocity(d[0], source), b = InverseWarp::velocity(d[1], target);
    return a && b;
}

void TimedWarp::tableVelocities(const Vec3d* p, const LocalTau* local, size_t n, size_t k,
                                Vec3d* source, Vec3d* target, bool* regular) const
{
    std::vector<VelocityKernel::Jet> jets[2] = {std::vector<VelocityKernel::Jet>(n),
                                                std::vector<VelocityKernel::Jet>(n)};
    mKernels[k]->jets(p, n, jets[0].data());
    mKernels[k + 1]->jets(p, n, jets[1].data());
    const double h = mTable.levels[k + 1] - mTable.levels[k];
    for (size_t i = 0; i < n; ++i) {
        const double f = std::clamp((local[i].tau - mTable.levels[k]) / h, 0.0, 1.0);
        Vec3d* out[2] = {&source[i], &target[i]};
        regular[i] = true;
        for (int s = 0; s < 2; ++s) {
            // The table's map differentiated: its slope between the levels, the chain rule.
            const Vec3d slope = (jets[1][i].point[s] - jets[0][i].point[s]) / h;
            InverseWarp::Derivatives d;
            d.jacobian = jets[0][i].jacobian[s] * (1.0 - f) + jets[1][i].jacobian[s] * f +
                         outer(slope, local[i].gradient);
            d.rate = slope * local[i].dt;
            regular[i] = InverseWarp::velocity(d, *out[s]) && regular[i];
        }
    }
}

void TimedWarp::velocities(const Vec3d* p, size_t n, Vec3d* source, Vec3d* target,
                           bool* regular) const
{
    if (mTolerance <= 0.0) {
        for (size_t i = 0; i < n; ++i) regular[i] = exactVelocity(p[i], source[i], target[i]);
        return;
    }
    // The moving points grouped by their interval of the table, each group through its two
    // levels' kernels at once; a place whose tau is clamped does not move.
    std::vector<LocalTau> local(n);
    std::map<size_t, std::vector<size_t>> groups;
    for (size_t i = 0; i < n; ++i) {
        local[i] = tauAt(p[i]);
        source[i] = target[i] = Vec3d(0.0);
        regular[i] = true;
        double f;
        if (local[i].dt != 0.0) groups[mTable.interval(local[i].tau, f)].push_back(i);
    }
    for (const auto& [k, members] : groups) {
        const size_t m = members.size();
        std::vector<Vec3d> points(m), s(m), t(m);
        std::vector<LocalTau> taus(m);
        std::unique_ptr<bool[]> ok(new bool[m]);
        for (size_t j = 0; j < m; ++j) {
            points[j] = p[members[j]];
            taus[j] = local[members[j]];
        }
        tableVelocities(points.data(), taus.data(), m, k, s.data(), t.data(), ok.get());
        for (size_t j = 0; j < m; ++j) {
            source[members[j]] = s[j];
            target[members[j]] = t[j];
            regular[members[j]] = ok[j];
        }
    }
}

bool TimedWarp::mayTouch(const CoordBBox& cube, const Occupancy* source,
                         const Occupancy* target) const
{
    if (!source && !target) return true;
    // The local times the cube's places can have: the delay at its centre, give or take the
    // steepest delay gradient over its half diagonal.
    const Vec3d centre = 0.5 * (cube.min().asVec3d() + cube.max().asVec3d());
    const double reach =
        mLocal.maxDelayGradient() * 0.5 * double(cube.dim().x()) * std::sqrt(3.0) * mVoxel;
    const double d = mLocal.delay(mXform.indexToWorld(centre)).d;
    const auto tau = [&](double delay) {
        return mLocal.fromDelay(Delay{delay, Vec3d(0.0)}, mT).tau;
    };
    double f;
    const size_t first = mTable.interval(tau(d + reach), f);
    size_t last = mTable.interval(tau(d - reach), f);
    if (f > 0.0) ++last;
    // Each level's map at a point is a convex combination of its pairs' affine maps, and the
    // table's a convex combination of two levels': the image lies in the box of all their images.
    Vec3d lo[2], hi[2];
    lo[0] = lo[1] = Vec3d(std::numeric_limits<double>::max());
    hi[0] = hi[1] = -lo[0];
    for (size_t k = first; k <= last; ++k)
        for (int side = 0; side < 2; ++side)
            for (const InverseWarp::Affine& a :
                 side == 0 ? mAffines[k].first : mAffines[k].second) {
                Vec3d a0, a1;
                affineImage(a, cube.min().asVec3d(), double(cube.dim().x()), a0, a1);
                lo[side] = minComponent(lo[side], a0);
                hi[side] = maxComponent(hi[side], a1);
            }
    return touches(source, lo[0], hi[0], kSamplerReach) ||
           touches(target, lo[1], hi[1], kSamplerReach);
}

std::vector<Coord> TimedWarp::candidates(const CoordBBox& box, const Occupancy* source,
                                         const Occupancy* target,
                                         const AdaptiveWarp::CellFilter* wanted) const
{
    std::vector<Coord> out;
    if (box.empty()) return out;
    const Coord lo(box.min().x() & -8, box.min().y() & -8, box.min().z() & -8);
    constexpr int kTop = AdaptiveWarp::kTopCell;
    const auto keep = [&](const CoordBBox& cube) {
        return (!wanted || (*wanted)(cube)) && mayTouch(cube, source, target);
    };
    for (int x = lo.x() & -kTop; x <= box.max().x(); x += kTop)
        for (int y = lo.y() & -kTop; y <= box.max().y(); y += kTop)
            for (int z = lo.z() & -kTop; z <= box.max().z(); z += kTop) {
                if (!keep(CoordBBox::createCube(Coord(x, y, z), kTop))) continue;
                for (int i = std::max(x, lo.x()); i < x + kTop && i <= box.max().x(); i += 8)
                    for (int j = std::max(y, lo.y()); j < y + kTop && j <= box.max().y(); j += 8)
                        for (int k = std::max(z, lo.z()); k < z + kTop && k <= box.max().z();
                             k += 8)
                            if (keep(CoordBBox::createCube(Coord(i, j, k), 8)))
                                out.emplace_back(i, j, k);
            }
    std::sort(out.begin(), out.end());
    return out;
}

/// A chunk of leaves being filled: each voxel's interval of the table and place along it, and the
/// blended points.
struct TimedWarp::Chunk {
    std::vector<Coord> origins; ///< sorted
    std::vector<WarpLeaf> leaves;
    std::vector<std::array<uint16_t, 512>> interval;
    std::vector<std::array<float, 512>> along;
    std::vector<std::pair<uint16_t, uint16_t>> levels; ///< the first and last level each needs

    size_t find(const Coord& origin) const
    {
        return size_t(std::lower_bound(origins.begin(), origins.end(), origin) - origins.begin());
    }
};

void TimedWarp::fillExact(Chunk& chunk, AdaptiveWarpStats& stats) const
{
    tbb::parallel_for(size_t(0), chunk.origins.size(), [&](size_t i) {
        WarpLeaf& leaf = chunk.leaves[i];
        leaf.origin = chunk.origins[i];
        leaf.errorBound = 0.0;
        std::map<double, std::shared_ptr<const InverseWarp>> warps; // by tau, within the leaf
        for (int n = 0; n < 512; ++n) {
            const Vec3d p = (leaf.origin + Coord(n >> 6, (n >> 3) & 7, n & 7)).asVec3d();
            const double tau = tauAt(p).tau;
            auto& warp = warps[tau];
            if (!warp) warp = warpAt(tau);
            Vec3d s, t;
            warp->map(p, s, t);
            leaf.set(n, Vec3f(s), Vec3f(t));
        }
    });
    stats.exactEvaluations += 512 * chunk.origins.size();
}

void TimedWarp::fillChunk(Chunk& chunk, AdaptiveWarpStats& stats, Interrupter* interrupter) const
{
    const size_t count = chunk.origins.size();
    chunk.leaves.resize(count);
    if (mTolerance <= 0.0) return fillExact(chunk, stats);
    chunk.interval.resize(count);
    chunk.along.resize(count);
    chunk.levels.resize(count);
    // Each voxel's interval, and the levels each leaf needs (a level at weight 0 is not needed).
    tbb::parallel_for(size_t(0), count, [&](size_t i) {
        uint16_t first = uint16_t(mTable.levels.size()), last = 0;
        double clamped; // a leaf whose places have not begun, or are done: one level
        const Vec3d centre = chunk.origins[i].asVec3d() + Vec3d(3.5);
        const bool whole = mLocal.clampedWithin(mXform.indexToWorld(centre),
                                                3.5 * std::sqrt(3.0) * mVoxel, mT, clamped);
        if (whole) {
            double f;
            const size_t k = mTable.interval(clamped, f);
            chunk.interval[i].fill(uint16_t(k));
            chunk.along[i].fill(float(f));
            first = last = uint16_t(f > 0.0 ? k + 1 : k);
        }
        for (int n = 0; !whole && n < 512; ++n) {
            const Vec3d p = (chunk.origins[i] + Coord(n >> 6, (n >> 3) & 7, n & 7)).asVec3d();
            double f;
            const size_t k = mTable.interval(tauAt(p).tau, f);
            chunk.interval[i][n] = uint16_t(k);
            chunk.along[i][n] = float(f);
            first = std::min(first, uint16_t(f < 1.0 ? k : k + 1));
            last = std::max(last, uint16_t(f > 0.0 ? k + 1 : k));
        }
        chunk.levels[i] = {first, last};
        WarpLeaf& leaf = chunk.leaves[i];
        leaf.origin = chunk.origins[i];
        leaf.errorBound = 0.0;
        std::fill(&leaf.s[0][0], &leaf.s[0][0] + 3 * 512, 0.0f);
        std::fill(&leaf.t[0][0], &leaf.t[0][0] + 3 * 512, 0.0f);
    });
    // Level by level: its leaves filled by its traversal and added at each voxel's weight.
    for (size_t level = 0; level < mTable.levels.size(); ++level) {
        std::vector<Coord> list;
        for (size_t i = 0; i < count; ++i)
            if (chunk.levels[i].first <= level && level <= chunk.levels[i].second)
                list.push_back(chunk.origins[i]);
        if (list.empty()) continue;
        mAdaptive[level]->fillLeaves(
            list,
            [&](const WarpLeaf& w) {
                const size_t i = chunk.find(w.origin);
                WarpLeaf& leaf = chunk.leaves[i];
                alignas(64) float weight[512];
                for (int n = 0; n < 512; ++n) {
                    const size_t k = chunk.interval[i][n];
                    const float f = chunk.along[i][n];
                    weight[n] = k == level ? 1.0f - f : (k + 1 == level ? f : 0.0f);
                }
                for (int c = 0; c < 3; ++c)
                    for (int n = 0; n < 512; ++n) {
                        leaf.s[c][n] += weight[n] * w.s[c][n];
                        leaf.t[c][n] += weight[n] * w.t[c][n];
                    }
                leaf.errorBound = std::max(leaf.errorBound, w.errorBound);
            },
            &stats, interrupter);
    }
    // A leaf between levels may be off by the table's estimate too.
    for (size_t i = 0; i < count; ++i)
        if (chunk.levels[i].first != chunk.levels[i].second)
            chunk.leaves[i].errorBound += mTable.error;
}

void TimedWarp::forEachLeaf(const CoordBBox& box, const Occupancy* source, const Occupancy* target,
                            const AdaptiveWarp::LeafFunction& fn, AdaptiveWarpStats* stats,
                            Interrupter* interrupter, const AdaptiveWarp::CellFilter* wanted) const
{
    const std::vector<Coord> all = candidates(box, source, target, wanted);
    constexpr size_t kChunk = 2048;
    AdaptiveWarpStats levels; // the levels' traversals
    std::atomic<uint64_t> visited{0};
    Chunk chunk; // its buffers kept from chunk to chunk
    for (size_t first = 0; first < all.size(); first += kChunk) {
        if (interrupter && interrupter->wasInterrupted(int(100 * first / all.size())))
            throw Interrupted();
        chunk.origins.assign(all.begin() + std::ptrdiff_t(first),
                             all.begin() + std::ptrdiff_t(std::min(all.size(), first + kChunk)));
        fillChunk(chunk, levels, interrupter);
        // The leaves whose points may reach either side, handed on.
        tbb::parallel_for(size_t(0), chunk.origins.size(), [&](size_t i) {
            const WarpLeaf& leaf = chunk.leaves[i];
            if (source || target) {
                Vec3f lo[2], hi[2];
                leafRange(leaf, lo, hi, KernelBuild::Baseline);
                const double margin = kSamplerReach + leaf.errorBound;
                if (!touches(source, Vec3d(lo[0]), Vec3d(hi[0]), margin) &&
                    !touches(target, Vec3d(lo[1]), Vec3d(hi[1]), margin))
                    return;
            }
            ++visited;
            fn(leaf);
        });
    }
    if (!stats) return;
    stats->leaves += visited;
    stats->exactEvaluations += levels.exactEvaluations;
    stats->nearEvaluations += levels.nearEvaluations;
    stats->allFarLeaves += levels.allFarLeaves;
    if (mTolerance > 0.0)
        stats->maxErrorVoxels =
            std::max(stats->maxErrorVoxels, levels.maxErrorVoxels + mTable.error);
}

} // namespace volmorph::detail
