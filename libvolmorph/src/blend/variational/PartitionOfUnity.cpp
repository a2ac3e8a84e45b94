#include "blend/variational/PartitionOfUnity.h"

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

double wendland(double d)
{
    return d >= 1.0 ? 0.0 : std::pow(1.0 - d, 4) * (4.0 * d + 1.0);
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
    if (constraints.size() <= options.coarse + options.leading) {
        pu.mCoarse = Interpolant::solveDense(constraints); // exact: no local level
        return pu;
    }
    pu.mCoarse =
        Interpolant::solveDense(coarseSubset(constraints, options.coarse, options.leading));
    std::vector<Constraint> residual = constraints;
    for (Constraint& c : residual) c.value -= pu.mCoarse(c.point);

    // The balls' lattice covers the shapes' constraints (not the leading ones, which the coarse
    // level interpolates and which lie far out), its occupied cells holding about a third of a
    // ball's constraints each.
    const std::vector<Constraint> shapes(constraints.begin() + long(options.leading),
                                         constraints.end());
    Eigen::Vector3d lo = spatial(shapes.front().point), hi = lo;
    for (const Constraint& c : shapes) {
        lo = lo.cwiseMin(spatial(c.point));
        hi = hi.cwiseMax(spatial(c.point));
    }
    const size_t wanted = std::max<size_t>(1, 3 * shapes.size() / options.perPatch);
    double h = (hi - lo).maxCoeff();
    for (int round = 0; round < 40 && occupiedCells(shapes, lo, h) < wanted; ++round) h *= 0.8;
    pu.mLo = lo - Eigen::Vector3d::Constant(h);
    pu.mCell = h;
    pu.mCells = ((hi - pu.mLo) / h).array().ceil().cast<int>() + 1;
    const double least = options.overlap * 0.5 * std::sqrt(3.0) * h;
    pu.mPatches.resize(size_t(pu.mCells.prod()));
    std::atomic<bool> stopped{false};
    tbb::parallel_for(size_t(0), pu.mPatches.size(), [&](size_t n) {
        if (stopped || (interrupter && interrupter->wasInterrupted())) {
            stopped = true;
            return;
        }
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
    for (const Patch& p : pu.mPatches) pu.mMaxRadius = std::max(pu.mMaxRadius, p.radius);
    return pu;
}

double PartitionOfUnity::local(const Point4& x, Point4* gradient) const
{
    const Eigen::Vector3d p = spatial(x);
    const Eigen::Array3d u = (p - mLo).array() / mCell;
    const double reach = mMaxRadius / mCell;
    Eigen::Array3i first, last;
    for (int a = 0; a < 3; ++a) {
        first[a] = std::clamp(int(std::floor(u[a] - reach)), 0, mCells[a] - 1);
        last[a] = std::clamp(int(std::floor(u[a] + reach)), 0, mCells[a] - 1);
    }
    // f = S / W with S = sum w_k r_k, W = sum w_k; grad f = (grad S - f grad W) / W.
    double sum = 0.0, weights = 0.0;
    Point4 gradSum = Point4::Zero(), gradWeights = Point4::Zero();
    for (int i = first.x(); i <= last.x(); ++i)
        for (int j = first.y(); j <= last.y(); ++j)
            for (int k = first.z(); k <= last.z(); ++k) {
                const Patch& patch = mPatches[size_t((i * mCells.y() + j) * mCells.z() + k)];
                const Eigen::Vector3d offset = p - patch.centre;
                const double d = offset.norm() / patch.radius;
                const double w = wendland(d);
                if (w <= 0.0) continue;
                Point4 gradR;
                const double r = patch.f.evaluate(x, gradient ? &gradR : nullptr);
                sum += w * r;
                weights += w;
                if (!gradient) continue;
                // psi'(d) = -20 d (1 - d)^3; d's gradient is offset / (|offset| R).
                Point4 gradW = Point4::Zero();
                if (d > 0.0)
                    gradW.head<3>() =
                        (-20.0 * std::pow(1.0 - d, 3) / (patch.radius * patch.radius)) * offset;
                gradSum += gradW * r + w * gradR;
                gradWeights += gradW;
            }
    if (weights > 0.0) {
        const double value = sum / weights;
        if (gradient) *gradient = (gradSum - value * gradWeights) / weights;
        return value;
    }
    // Beyond every ball: the nearest lattice patch's fit, extended.
    const Eigen::Array3i c = u.floor().cast<int>().max(0).min(mCells - 1);
    const Patch& nearest = mPatches[size_t((c.x() * mCells.y() + c.y()) * mCells.z() + c.z())];
    if (gradient) *gradient = nearest.f.gradient(x);
    return nearest.f(x);
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
