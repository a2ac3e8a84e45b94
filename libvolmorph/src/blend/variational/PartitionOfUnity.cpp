#include "blend/variational/PartitionOfUnity.h"

#include "blend/Abandonable.h"
#include "blend/variational/Constraints.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numeric>
#include <set>
#include <stdexcept>
#include <thread>

namespace volmorph::detail::variational {
namespace {

/// The weight of a null fit (0 everywhere) beside the balls': the local level fades to 0 away
/// from them. At a constraint, which its own ball weighs about 1, it leaves a thousandth of the
/// coarse level's residual there.
constexpr double kNullWeight = 1e-3;

double wendland(double d)
{
    const double e = 1.0 - d, e2 = e * e;
    return d >= 1.0 ? 0.0 : e2 * e2 * (4.0 * d + 1.0);
}

Eigen::Vector3d spatial(const Point4& p)
{
    return p.head<3>();
}

/// Lattice cells (of size h) holding at least one constraint.
size_t occupiedCells(const std::vector<Constraint>& constraints, const Eigen::Vector3d& lo,
                     double h)
{
    std::set<std::array<long, 3>> cells;
    for (const Constraint& c : constraints) {
        const Eigen::Vector3d u = (spatial(c.point) - lo) / h;
        cells.insert({long(std::floor(u.x())), long(std::floor(u.y())), long(std::floor(u.z()))});
    }
    return cells.size();
}

/// The ball around `centre`: its radius (at least `least`, and enough to hold `perPatch`
/// constraints) and the constraints its fit uses: those inside it and, when they all lie at one
/// time, the nearest perPatch / 4 of other times too (the fit's t must be determined; the ball is
/// not grown to reach them, which made balls near one shape hold thousands of the other's).
std::pair<double, std::vector<size_t>> ball(const std::vector<Constraint>& constraints,
                                            const Eigen::Vector3d& centre, size_t perPatch,
                                            double least)
{
    std::vector<std::pair<double, size_t>> byDistance(constraints.size());
    for (size_t i = 0; i < constraints.size(); ++i)
        byDistance[i] = {(spatial(constraints[i].point) - centre).norm(), i};
    std::sort(byDistance.begin(), byDistance.end());
    const size_t count = std::min(perPatch, byDistance.size());
    const double radius = std::max(least, byDistance[count - 1].first) * (1.0 + 1e-9);
    std::vector<size_t> members;
    const double firstTime = constraints[byDistance.front().second].point[3];
    bool oneTime = true;
    for (const auto& [d, i] : byDistance) {
        if (d > radius) break;
        members.push_back(i);
        oneTime = oneTime && constraints[i].point[3] == firstTime;
    }
    if (oneTime) {
        size_t others = 0;
        for (const auto& [d, i] : byDistance)
            if (constraints[i].point[3] != firstTime) {
                members.push_back(i);
                if (++others >= perPatch / 4) break;
            }
    }
    return {radius, members};
}

} // namespace

namespace {

/// The coarse level's constraints: the first `leading`, and an even subset of the others, every
/// stride-th group (sampleConstraints writes each surface point followed by its partners),
/// about `count` in all.
std::vector<Constraint> coarseSubset(const std::vector<Constraint>& constraints, size_t count,
                                     size_t leading)
{
    const size_t rest = constraints.size() - leading;
    const size_t stride = (rest + count - 1) / count;
    std::vector<Constraint> subset(constraints.begin(), constraints.begin() + long(leading));
    for (size_t i = 0; i < rest; ++i)
        if ((i / kConstraintsPerPoint) % stride == 0) subset.push_back(constraints[leading + i]);
    return subset;
}

} // namespace

uint64_t PartitionOfUnity::estimateBytes(size_t count, const PartitionOptions& options)
{
    // Measured (BENCHMARKS.md) about 1 KiB a constraint for the balls' fits; twice that here.
    const uint64_t threads = std::max(1u, std::thread::hardware_concurrency());
    const uint64_t perThread =
        denseSolveBytes(4 * options.perPatch) + uint64_t(count) * 2 * sizeof(double);
    return denseSolveBytes(std::min(count, options.coarse + options.leading)) +
           uint64_t(count) * 2048 + threads * perThread;
}

PartitionOfUnity PartitionOfUnity::solve(const std::vector<Constraint>& constraints,
                                         const PartitionOptions& options, Interrupter* interrupter)
{
    PartitionOfUnity pu;
    if (options.leading > constraints.size())
        throw std::invalid_argument("PartitionOfUnity: more leading constraints than constraints");
    // The dense solves take about a second at 2000 and Eigen's LU takes no interrupter: they run
    // abandonable, so that a stop request is answered at once.
    const auto dense = [interrupter](std::vector<Constraint> c) {
        return abandonable([c = std::move(c)](Interrupter&) { return Interpolant::solveDense(c); },
                           interrupter);
    };
    if (constraints.size() <= options.coarse + options.leading) {
        pu.mCoarse = dense(constraints); // exact: no local level
        return pu;
    }
    pu.mCoarse = dense(coarseSubset(constraints, options.coarse, options.leading));
    std::vector<Constraint> residual = constraints;
    for (Constraint& c : residual) c.value -= pu.mCoarse(c.point);

    // The balls' lattice covers the shapes' constraints (not the leading ones, which the coarse
    // level interpolates and which lie far out), its occupied cells holding about a sixth of a
    // ball's constraints each (a third: balls of about 850 where 425 do, dino-to-eight at 128
    // across: the setup 1.9x and a frame 1.2x slower, the zero set no closer to the dense
    // solve's; a tenth: more balls grown past their least radius, slower again).
    const std::vector<Constraint> shapes(constraints.begin() + long(options.leading),
                                         constraints.end());
    Eigen::Vector3d lo = spatial(shapes.front().point), hi = lo;
    for (const Constraint& c : shapes) {
        lo = lo.cwiseMin(spatial(c.point));
        hi = hi.cwiseMax(spatial(c.point));
    }
    const size_t wanted = std::max<size_t>(1, 6 * shapes.size() / options.perPatch);
    double h = (hi - lo).maxCoeff();
    for (int round = 0; round < 40 && occupiedCells(shapes, lo, h) < wanted; ++round) h *= 0.8;
    pu.mLo = lo - Eigen::Vector3d::Constant(h);
    pu.mCell = h;
    pu.mCells = ((hi - pu.mLo) / h).array().ceil().cast<int>() + 1;
    const double least = options.overlap * 0.5 * std::sqrt(3.0) * h;
    pu.mPatches.resize(size_t(pu.mCells.prod()));
    // Balls only where the shapes are: a ball in an empty cell grows until it reaches them, and
    // then weighs on every value near them (93 balls and 31,616 centres a cell on dino-to-eight at
    // 128 across, against a few near the surface without them). Away from every ball the local
    // level fades to 0 (kNullWeight) and the coarse level stands alone.
    std::vector<char> occupied(pu.mPatches.size(), 0);
    for (const Constraint& c : shapes) {
        const Eigen::Array3i cell =
            ((spatial(c.point) - pu.mLo) / h).array().floor().cast<int>().max(0).min(pu.mCells - 1);
        occupied[size_t((cell.x() * pu.mCells.y() + cell.y()) * pu.mCells.z() + cell.z())] = 1;
    }
    std::atomic<bool> stopped{false};
    tbb::parallel_for(size_t(0), pu.mPatches.size(), [&](size_t n) {
        if (stopped || (interrupter && interrupter->wasInterrupted())) {
            stopped = true;
            return;
        }
        if (!occupied[n]) return; // radius 0: no ball
        const int k = int(n % size_t(pu.mCells.z())),
                  j = int(n / size_t(pu.mCells.z())) % pu.mCells.y(),
                  i = int(n / size_t(pu.mCells.z() * pu.mCells.y()));
        const Eigen::Vector3d centre = pu.mLo + h * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        auto [radius, members] = ball(residual, centre, options.perPatch, least);
        std::vector<Constraint> local;
        local.reserve(members.size());
        for (size_t m : members) local.push_back(residual[m]);
        pu.mPatches[n] = Patch{centre, radius, Interpolant::solveDense(local)};
    });
    if (stopped) throw Interrupted();
    pu.listBallsPerCell();
    return pu;
}

void PartitionOfUnity::listBallsPerCell()
{
    std::vector<std::vector<uint32_t>> lists(mPatches.size());
    for (size_t n = 0; n < mPatches.size(); ++n) { // in order: each list sorted
        const Patch& patch = mPatches[n];
        if (patch.radius <= 0.0) continue;
        const Eigen::Array3d lo = (patch.centre.array() - patch.radius - mLo.array()) / mCell,
                             hi = (patch.centre.array() + patch.radius - mLo.array()) / mCell;
        const Eigen::Array3i first = lo.floor().cast<int>().max(0),
                             last = hi.floor().cast<int>().min(mCells - 1);
        for (int i = first.x(); i <= last.x(); ++i)
            for (int j = first.y(); j <= last.y(); ++j)
                for (int k = first.z(); k <= last.z(); ++k) {
                    // The ball reaches the cell when the cell's nearest point is inside it.
                    const Eigen::Array3d cellLo = mLo.array() + mCell * Eigen::Array3d(i, j, k);
                    const Eigen::Array3d nearest =
                        patch.centre.array().max(cellLo).min(cellLo + mCell);
                    if ((nearest - patch.centre.array()).matrix().norm() < patch.radius)
                        lists[size_t((i * mCells.y() + j) * mCells.z() + k)].push_back(uint32_t(n));
                }
    }
    mCellStart.assign(1, 0);
    for (const auto& list : lists) {
        mCellPatches.insert(mCellPatches.end(), list.begin(), list.end());
        mCellStart.push_back(uint32_t(mCellPatches.size()));
    }
}

double PartitionOfUnity::local(const Point4& x, Point4* gradient, double* rate) const
{
    const Eigen::Vector3d p = spatial(x);
    const Eigen::Array3d u = (p - mLo).array() / mCell;
    // The balls that reach the point's cell (its projection's, beyond the lattice: a ball holding
    // the point holds that projection too, its centre lying in the lattice).
    const Eigen::Array3i c = u.floor().cast<int>().max(0).min(mCells - 1);
    const size_t cell = size_t((c.x() * mCells.y() + c.y()) * mCells.z() + c.z());
    // f = S / W with S = sum w_k r_k, W = sum w_k; grad f = (grad S - f grad W) / W.
    double sum = 0.0, weights = 0.0, rateSum = 0.0;
    Point4 gradSum = Point4::Zero(), gradWeights = Point4::Zero();
    for (uint32_t n = mCellStart[cell]; n < mCellStart[cell + 1]; ++n) {
        const Patch& patch = mPatches[mCellPatches[n]];
        const Eigen::Vector3d offset = p - patch.centre;
        const double d = offset.norm() / patch.radius;
        const double w = wendland(d);
        if (w <= 0.0) continue;
        Point4 gradR;
        double rateR = 0.0;
        const double r = gradient ? patch.f.evaluate(x, &gradR)
                                  : patch.f.evaluateWithRate(x, rate ? &rateR : nullptr);
        sum += w * r;
        weights += w;
        if (rate) rateSum += w * rateR;
        if (!gradient) continue;
        // psi'(d) = -20 d (1 - d)^3; d's gradient is offset / (|offset| R).
        Point4 gradW = Point4::Zero();
        if (d > 0.0)
            gradW.head<3>() =
                (-20.0 * (1.0 - d) * (1.0 - d) * (1.0 - d) / (patch.radius * patch.radius)) *
                offset;
        gradSum += gradW * r + w * gradR;
        gradWeights += gradW;
    }
    // The null weight: 0 beyond every ball, continuously.
    const double value = sum / (weights + kNullWeight);
    if (gradient) *gradient = (gradSum - value * gradWeights) / (weights + kNullWeight);
    if (rate) *rate = rateSum / (weights + kNullWeight);
    return value;
}

double PartitionOfUnity::operator()(const Point4& x) const
{
    return evaluate(x, nullptr);
}

Point4 PartitionOfUnity::gradient(const Point4& x) const
{
    Point4 g;
    evaluate(x, &g);
    return g;
}

double PartitionOfUnity::evaluateLocal(const Point4& x, double* rate) const
{
    if (mPatches.empty()) {
        if (rate) *rate = 0.0;
        return 0.0;
    }
    return local(x, nullptr, rate);
}

double PartitionOfUnity::evaluate(const Point4& x, Point4* gradient) const
{
    double value = mCoarse.evaluate(x, gradient);
    if (mPatches.empty()) return value;
    Point4 l;
    value += local(x, gradient ? &l : nullptr);
    if (gradient) *gradient += l;
    return value;
}

} // namespace volmorph::detail::variational
