// A two-level partition-of-unity approximation of the variational function (issue 40's fast
// solver; after Ohtake, Belyaev and Seidel's multi-level PU implicits): a coarse global
// interpolant through an even subset of the constraints (each surface point with its partners)
// and every leading (exterior) one, then the residual at every constraint fitted locally. The
// shapes' constraints are covered by overlapping balls centred on the occupied cells of a
// lattice; each ball's constraints (those whose (x, y, z) lies inside it, at every t) get their
// own small r^3 interpolant of the residual (Interpolant.h, a dense solve of a few hundred),
// blended by Wendland's C2 weights, normalized with a small null weight w_0 (a fit that is 0):
//
//   f(x) = g(x) + sum_k w_k(x) r_k(x) / (w_0 + sum_k w_k(x)),   w_k(x) = psi(|x_xyz - c_k| / R_k),
//   psi(d) = (1 - d)^4 (4 d + 1) for d < 1,
//
// so that away from every ball f is the coarse level's, continuously.
//
// The coarse level carries what the local fits cannot see: how the shapes at different times
// join far from both (without it, a sphere into two spheres put the zero set up to 0.8 voxel from
// the dense solve's; with it 0.03, BENCHMARKS.md).
//
// A ball grows until it holds `perPatch` constraints from at least two distinct times (t must be
// determined inside it). It solves a different system from the global one: what it must give is
// the same zero set (issue 40: within 0.1 voxel of the dense solve's), at a cost linear in the
// number of constraints.
#pragma once

#include "blend/variational/Interpolant.h"

#include <volmorph/core/Interrupter.h>

#include <vector>

namespace volmorph::detail::variational {

struct PartitionOptions {
    size_t perPatch = 300; ///< constraints each ball holds at least
    double overlap = 1.5;  ///< a ball's least radius, in half-diagonals of a lattice cell
    size_t coarse = 2000;  ///< constraints in the global coarse level (all, when fewer)
    /// The first `leading` constraints all go into the coarse level, beside its even subset of
    /// the others (the exterior constraints, which hold the function's sign far from the shapes).
    size_t leading = 0;
};

class PartitionOfUnity {
public:
    /// Throws std::invalid_argument as Interpolant::solveDense does (too few constraints, or
    /// all at one time); Interrupted when `interrupter` asks to stop.
    static PartitionOfUnity solve(const std::vector<Constraint>& constraints,
                                  const PartitionOptions& options = {},
                                  Interrupter* interrupter = nullptr);

    /// An upper estimate of the bytes solve() holds at its peak for `count` constraints: the
    /// coarse level's dense solve, the balls' fits (each constraint in a few balls, their centres
    /// and weights), and each thread's sort and dense solve of one ball.
    static uint64_t estimateBytes(size_t count, const PartitionOptions& options = {});

    /// f(x): the coarse level, and the balls' fits where they reach (faded by a small null weight,
    /// so 0 beyond them).
    double operator()(const Point4& x) const;
    /// (df/dx, df/dy, df/dz, df/dt'), t' = t * time_scale: the weights' derivatives included.
    Point4 gradient(const Point4& x) const;
    /// f(x), and its gradient into `gradient` when not null: one pass for both.
    double evaluate(const Point4& x, Point4* gradient) const;
    /// The coarse level alone (its centres a few thousand, spread over the shapes at their
    /// times), and the balls' level alone: evaluate() is their sum. evaluateLocal's `rate`, when
    /// given, gets df/dt' there (evaluate()'s gradient's last component, the same bits).
    const Interpolant& coarse() const { return mCoarse; }
    double evaluateLocal(const Point4& x, double* rate) const;
    size_t patchCount() const { return mPatches.size(); }

private:
    struct Patch {
        Eigen::Vector3d centre;
        double radius = 0.0;
        Interpolant f;
    };
    /// The local level's value, and its gradient when `gradient` is given, or only df/dt' when
    /// `rate` is (the weights do not depend on t).
    double local(const Point4& x, Point4* gradient, double* rate = nullptr) const;
    /// mCellStart and mCellPatches from the patches.
    void listBallsPerCell();

    Interpolant mCoarse;
    std::vector<Patch> mPatches; ///< lattice order: k fastest
    Eigen::Vector3d mLo{0.0, 0.0, 0.0};
    Eigen::Array3i mCells{0, 0, 0};
    double mCell = 1.0;
    /// The balls reaching each lattice cell, by index, in order: cell n's are
    /// mCellPatches[mCellStart[n] .. mCellStart[n + 1]).
    std::vector<uint32_t> mCellStart, mCellPatches;
};

} // namespace volmorph::detail::variational
