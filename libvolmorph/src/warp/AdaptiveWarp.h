// The approximated inverse warp and the sparse output domain, found together.
//
// The exact warp is p(x) = sum w_i(x) A_i(x) / sum w_i(x): affine maps A_i blended by weights
// w_i = scale_i (offset + d_i)^-b of the distances d_i to the interpolated elements. Its cost is
// O(pairs) per voxel. The approximation works leaf by leaf (8^3 voxels, output index space):
//
// 1. The exact sums W = sum w_i and N = sum w_i A_i are evaluated once at every corner of every
//    candidate leaf, on a lattice 8 voxels apart shared by neighbouring leaves.
// 2. In a leaf, the warp is written relative to the affine map B of its dominant pair (the
//    largest weight at the leaf's centre): p = B + sum w_i R_i / W with R_i = A_i - B. The pairs
//    are split into near ones (E), evaluated exactly at every voxel, and far ones (F), whose
//    sums G = sum_F w_i R_i and W_F = sum_F w_i are smooth over the leaf and interpolated
//    trilinearly from the corners (exact there): p~ = B + (N_E + I[G]) / (W_E + I[W_F]).
//    A pair whose weight is constant over the leaf (a box containing it) is far and exact.
// 3. Which pairs are near follows from an a-priori bound of the interpolation error, not from
//    samples (samples between lattice points miss the kinks of d on the elements' boundaries and
//    the bending on the scale of d + offset). For u in C^{1,1}, trilinear interpolation over a
//    cube of side h errs by at most h^2/8 (sup |u_xx| + sup |u_yy| + sup |u_zz|). With
//    |grad d| = 1 and Hess d positive semidefinite with grad d as a null vector and eigenvalues
//    at most 1/d (the distance to a convex set), along each axis a over the leaf
//      |d_a w_i| <= b w_i / r_i |d_a d_i|,
//      |d_aa w_i| <= w_i max(b (b + 1) / r_i^2 (d_a d_i)^2, b / r_i (1 - (d_a d_i)^2) / d_i)
//    (the two terms of d_aa w_i have opposite signs), r_i = offset + d_i, each at the leaf's
//    smallest distance to element i, with the range of d_a d_i from the turn of grad d. Along
//    each axis the sups fall off away from the element, at least as (1 + kappa s)^-(b + 1) at
//    s voxels from the nearest face (kappa = |d_a d_i| / r_i there, by the tangent plane of d);
//    integrating the linear interpolant's Peano kernel against that profile, in closed form,
//    shrinks axis a's share of the h^2/8 by (2 / (q (q + 1)))^2, q = sqrt(1 + kappa h). And
//      |p~ - p| <= (h^2/8) sum_F [(|R_i| + |rho|) H_i + 2 |M_i - M_B| |grad w_i|]
//                  / max(W_min - (h^2/8) sum_F H_i, W_floor),   H_i = sum_a sup |d_aa w_i|,
//    rho = p - B (a convex combination of the R_i), |R_i| and W_min bounded over the leaf, both
//    sides (w_i at least at d_i <= |x - (c - d_c grad d_c)|, the centre's nearest point on the
//    element); with every pair far, the interpolated W is at least W_floor, the corners'
//    smallest W. Where this all-far bound is finite, a second pass tightens it: a far pair's share
//    is (R_i(c) - rho) (I[w_i] - w_i) + (M_i - M_B)(I[w_i (x - c)] - w_i (x - c)), c the centre,
//    and the all-far interpolant's rho lies in the hull of the corners' rho_k, within the bound
//    of the true rho, so |R_i| + |rho| becomes |R_i(c) - rho_0| + (hull radius) + bound.
//    Pairs join E, largest term first, until the bound is within the tolerance. An
//    element that touches the leaf (d_i = 0 somewhere, not containing it) has a kink there and
//    is always near. One pair is its affine map: R = 0, no error, nothing near.
// 4. The same bound decides the domain without evaluating any voxel. With every pair far, the
//    interpolant is B + I[G] / I[W], and I[G] / I[W] is a convex combination of the corners'
//    residuals, so the image lies within B(leaf) + their hull, widened by the bound; otherwise
//    p = B + rho lies within B(leaf) widened by |rho|max. A leaf whose image misses every
//    occupied block of both sides (widened by the sampler's reach) is skipped; blocks of 4^3
//    and then of 2^3 leaves are judged first, from every 4th and every other lattice point. A
//    leaf kept only by the bound's margin is checked again on its filled points.
// 5. The arithmetic runs on 8-lane vectors (GCC's vector extension). The bound's per-pair terms
//    take 8 pairs at a time in single precision (its rounding, about 1e-7 of each term, is far
//    inside its slack; weights beyond single precision send the leaf to the exact path), their
//    sums over pairs kept per lane in double (padding lanes masked) and the corners' residuals 4
//    corners at a time in double; the lattice's exact sums take 4 pairs at a time in double.
//    Each leaf is filled by one kernel on rows of 8 voxels along z (one vector each): the far
//    sums of every row (along x on the leaf's edges, then each slice's first and last rows, the
//    rows between one step along y apart), then each near pair added over all rows (its frame
//    coordinates and residuals walked the same way, affine in the voxel; its rows' square roots
//    and divisions independent, so they overlap), then the points, in single precision as they
//    are stored (with no near pair, a third of the leaves, the rows' sums go straight into the
//    points, unstored: the same operations and bits). Each of these is compiled
//    for AVX2, for AVX2 with AVX-512VL (32 vector registers) and for the baseline and picked by
//    the CPU, with the same bits from all (no FMA contraction in their units). The code is in
//    src/warp/adaptive/: PairColumns, ErrorBound (3), DomainTest (4), LeafKernel and LatticeSums
//    (5), and AdaptiveWarp.cpp, the traversal (1-4 in order). Measurements: BENCHMARKS.md.
//
// Lerios et al. (1995) interpolated the warp over an adaptive grid checked at the next finer
// lattice; here no sample decides the error, and the exact warp is evaluated at about one point
// per leaf plus the near pairs at the voxels that need them.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/core/Math.h>
#include <volmorph/Warp.h>

#include "Occupancy.h"

#include <openvdb/openvdb.h>

#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <vector>

namespace volmorph::detail {

/// Warped positions of one output leaf's 8^3 voxels, in the index space of source and target.
/// Voxel (i, j, k) of the leaf is n = (i * 8 + j) * 8 + k, as in OpenVDB's leaf nodes. Stored
/// channel-major (the warp's loops write whole channels).
struct WarpLeaf {
    openvdb::Coord origin;
    /// What the points may be off the exact warp's (voxels): the a-priori bound, 0 where exact.
    double errorBound = 0.0;
    alignas(64) float s[3][512]; ///< source side: x, y, z of each voxel
    alignas(64) float t[3][512]; ///< target side
    Vec3f source(int n) const { return Vec3f(s[0][n], s[1][n], s[2][n]); }
    Vec3f target(int n) const { return Vec3f(t[0][n], t[1][n], t[2][n]); }
    void set(int n, const Vec3f& ps, const Vec3f& pt)
    {
        for (int c = 0; c < 3; ++c) {
            s[c][n] = ps[c];
            t[c][n] = pt[c];
        }
    }
};

struct AdaptiveWarpStats {
    double maxErrorVoxels = 0.0; ///< the largest error bound of an interpolated leaf (voxels)
    uint64_t exactEvaluations =
        0;                        ///< exact warp evaluations (lattice points, exact leaves' voxels)
    uint64_t nearEvaluations = 0; ///< near pairs evaluated at single voxels (one pair each)
    uint64_t allFarLeaves = 0;    ///< interpolated leaves with no near pair
    uint64_t leaves = 0;          ///< leaves visited (the candidate domain)
};

/// The builds of the leaf kernel, the bound and the lattice's sums, least capable first: the
/// baseline, AVX2, and AVX2 with AVX-512VL (its 32 vector registers). All give the same bits.
enum class KernelBuild { Baseline, Avx2, Avx512 };
/// The most capable build this CPU has.
KernelBuild bestKernelBuild();

// The implementation's types (src/warp/adaptive/).
struct LatticePoint;
struct Lattice;
struct WarpColumns;
struct WarpContext;

class AdaptiveWarp {
public:
    /// `warp` must map output index space to source and target index space (built with unit
    /// 1 / voxel size). Tolerance 0 means exact: every voxel is evaluated. The kernels run in the
    /// most capable build the CPU has, at most `limit` (tests compare the builds with it).
    AdaptiveWarp(const InverseWarp& warp, double toleranceVoxels,
                 KernelBuild limit = KernelBuild::Avx512);
    ~AdaptiveWarp();

    /// The build the kernels run in.
    KernelBuild kernelBuild() const { return mBuild; }

    using LeafFunction = std::function<void(const WarpLeaf&)>;
    /// "Is any leaf of this cell (output index space) wanted?"; cells answered no are skipped
    /// before any of their points is evaluated.
    using CellFilter = std::function<bool(const openvdb::CoordBBox&)>;

    /// Calls fn, in parallel, for every leaf in `box` (output index space) that may be non-empty
    /// by the occupancies (nullptr on both: every leaf of the box) and that `wanted` (if given)
    /// accepts. Deterministic: each leaf's positions depend only on the leaf, not on threads or
    /// order.
    void forEachLeaf(const openvdb::CoordBBox& box, const Occupancy* source,
                     const Occupancy* target, const LeafFunction& fn,
                     AdaptiveWarpStats* stats = nullptr, Interrupter* interrupter = nullptr,
                     const CellFilter* wanted = nullptr) const;

    /// Calls fn, in parallel, for each of `leaves` (their origins, output index space), none
    /// culled: the traversal's lattice and fill for a list made elsewhere (TimedWarp.h).
    void fillLeaves(const std::vector<openvdb::Coord>& leaves, const LeafFunction& fn,
                    AdaptiveWarpStats* stats = nullptr, Interrupter* interrupter = nullptr) const;

    /// Leaves are first gathered in cells this many voxels on a side (filtered, and culled by the
    /// hull of every pair's affine image).
    static constexpr int kTopCell = 64;

private:
    /// One forEachLeaf call's steps (adaptive/AdaptiveWarp.cpp).
    class Traversal;

    // adaptive/ErrorBound.cpp
    /// The bound's terms for the cube of `size` (8, 16 or 32) voxels at origin, from the exact
    /// sums at its corners (bit 0: +x, bit 1: +y, bit 2: +z), into ctx.
    void analyze(WarpContext& ctx, const LatticePoint* const corners[8],
                 const openvdb::Coord& origin, int size) const;
    /// analyze() and exactSums() in their builds (see KernelBuild): one body, inlined into each.
    void analyzeBody(WarpContext& ctx, const LatticePoint* const corners[8],
                     const openvdb::Coord& origin, int size) const;
    void analyzeBaseline(WarpContext& ctx, const LatticePoint* const corners[8],
                         const openvdb::Coord& origin, int size) const;
    void analyzeAvx2(WarpContext& ctx, const LatticePoint* const corners[8],
                     const openvdb::Coord& origin, int size) const;
    void analyzeAvx512(WarpContext& ctx, const LatticePoint* const corners[8],
                       const openvdb::Coord& origin, int size) const;
    /// Marks the analysed cube's near pairs; returns its bound.
    double selectNear(WarpContext& ctx, size_t& nearCount) const;

    // adaptive/LatticeSums.cpp
    /// The exact warp's unnormalized sums W, S and T at x (map() gives S / W and T / W), by the
    /// pairs' columns; false where x lies on an element and the weight law has no offset.
    bool exactSums(const Vec3d& x, LatticePoint& out) const;
    bool exactSumsBody(const Vec3d& x, LatticePoint& out) const;
    bool exactSumsBaseline(const Vec3d& x, LatticePoint& out) const;
    bool exactSumsAvx2(const Vec3d& x, LatticePoint& out) const;
    bool exactSumsAvx512(const Vec3d& x, LatticePoint& out) const;

    // adaptive/DomainTest.cpp
    /// False when the analysed cube's image misses both sides' occupied blocks.
    bool mayTouch(WarpContext& ctx, const openvdb::Coord& origin, int size) const;

    // adaptive/AdaptiveWarp.cpp
    /// Fills the analysed leaf at origin: far sums interpolated, near pairs evaluated.
    void fill(WarpContext& ctx, const openvdb::Coord& origin) const;
    void leaf(WarpContext& ctx, const Lattice& lattice, const openvdb::Coord& origin) const;
    void exactLeaf(WarpContext& ctx) const;
    void identityLeaf(WarpContext& ctx) const;

    const InverseWarp& mWarp;
    double mTolerance;
    KernelBuild mBuild;
    std::vector<InverseWarp::Affine> mSource, mTarget; ///< each pair's affine map on each side
    std::unique_ptr<const WarpColumns> mColumns;       ///< the interpolated elements, by column
    std::vector<size_t> mByType; ///< the pairs by type, then by index (the kernel's order)
};

} // namespace volmorph::detail
