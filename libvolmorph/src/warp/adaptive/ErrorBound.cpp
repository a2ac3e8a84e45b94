// The error bound over a cube (AdaptiveWarp.h, step 3), as named steps: the corners' weights, each
// pair's weight bounds, the dominant pair, the residuals, each far pair's share, and, where the
// all-far bound is finite, the corners' residuals and a tighter second pass. Then selectNear():
// pairs join the near ones, largest share first, until the bound holds the tolerance.
#include "warp/adaptive/ErrorBound.h"

#include "warp/adaptive/Context.h"
#include "warp/adaptive/PairColumns.h"
#include "warp/adaptive/Simd.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::detail {
namespace {

using openvdb::Coord;

/// One analysis of the cube [o, o + size]^3 (a leaf: its voxels and its far corners) into ctx;
/// see AdaptiveWarp.h for the derivation. The per-pair loops take 8 pairs at a time in single
/// precision; the sums over pairs are in double. Every step is inlined into each build.
class CubeAnalysis {
public:
    using C = PairBounds::Column;
    using PC = PairColumns<float>;

    VOLMORPH_ALWAYS_INLINE CubeAnalysis(WarpContext& ctx, const Coord& origin, int size,
                                        const InverseWarp& warp, const WarpColumns& columns)
        : ctx(ctx), warp(warp), columns(columns), col(columns.bound), n(warp.pairCount()),
          padded(col.padded), o(origin.asVec3d()), h(size), halfDiagonal(0.5 * h * std::sqrt(3.0)),
          centre(o + Vec3d(0.5 * h)), cf(centre), hf(float(h)), halfDiagonalF(float(halfDiagonal)),
          offset(float(warp.weightOffset())), b(float(warp.weightExponent())),
          inverseSquare(warp.weighting() == Weighting::InverseSquare), pb(ctx.bounds)
    {
        pb.resize(padded);
    }

    /// The corners' smallest total weight W, where every corner's sums are finite.
    VOLMORPH_ALWAYS_INLINE void corners(const LatticePoint* const corners[8])
    {
        ctx.cornersOk = true;
        ctx.wCornerMin = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 8; ++k) {
            ctx.corner[k] = corners[k];
            ctx.cornersOk = ctx.cornersOk && corners[k]->ok;
            if (ctx.cornersOk) ctx.wCornerMin = std::min(ctx.wCornerMin, corners[k]->w);
        }
        // Less a margin for the rounding of W to single precision in the kernel.
        ctx.wCornerMin = ctx.cornersOk ? ctx.wCornerMin * (1.0 - 1e-6) : 0.0;
    }

    VOLMORPH_ALWAYS_INLINE inline void weights();
    VOLMORPH_ALWAYS_INLINE inline void residuals(const std::vector<InverseWarp::Affine>& source,
                                                 const std::vector<InverseWarp::Affine>& target);
    VOLMORPH_ALWAYS_INLINE inline void shares();
    VOLMORPH_ALWAYS_INLINE inline void cornerResiduals(const LatticePoint* const corners[8]);
    VOLMORPH_ALWAYS_INLINE inline void tighten();

private:
    /// One group's distances from the centre, their gradient, and their range over the cube.
    struct GroupDistance {
        v8i inside; ///< a box contains the whole cube
        v8f d, dMin, dMax, g[3];
    };
    VOLMORPH_ALWAYS_INLINE inline GroupDistance groupDistance(const PC::Group& cg) const;
    /// One group's distances and weight bounds (weights()); returns the weights at the centre.
    VOLMORPH_ALWAYS_INLINE inline v8f groupWeights(size_t i, WideSum& wMinTotal, v8i& steep);

    WarpContext& ctx;
    const InverseWarp& warp;
    const WarpColumns& columns;
    const PairColumns<float>& col;
    const size_t n, padded;
    const Vec3d o;
    const double h, halfDiagonal;
    const Vec3d centre;
    const Vec3f cf;
    const float hf, halfDiagonalF;
    const float offset, b;
    const bool inverseSquare;
    PairBounds& pb;
    const v8f zero = splat8(0.0f), one = splat8(1.0f),
              infinity = splat8(std::numeric_limits<float>::infinity());
    // Found by the steps, for the later ones.
    const InverseWarp::Affine* bS = nullptr; ///< the dominant pair's maps
    const InverseWarp::Affine* bT = nullptr;
    const float* slope = nullptr; ///< the slopes against the dominant pair
    float rhoMaxF = 0.0f;
    float hh8 = 0.0f; ///< h^2/8 (kBoundScale)
    double curveTotal = 0.0;
    double radius[2] = {0.0, 0.0}; ///< the corners' residuals' largest distance to their centre
};

/// Per pair: frame coordinates q of the centre, the distance dc = |max(|q| - half, 0)| (half 0
/// on the axes a type does not extend along), its gradient g in index axes, the smallest
/// distance over the cube, and whether a box contains the whole cube (d = 0, w constant)
/// (groupDistance); then the weights' bounds (groupWeights). Over the pairs: the smallest total
/// weight, whether any weight is too steep (below kTinyRadius or beyond single precision: the leaf
/// is then evaluated exactly), and the dominant pair (the largest weight at the centre; the first
/// such pair).
void CubeAnalysis::weights()
{
    WideSum wMinTotal;
    v8i steep{}, bestIndex{};
    v8f best = splat8(-1.0f);
    const v8i laneIndex = {0, 1, 2, 3, 4, 5, 6, 7};
    for (size_t i = 0; i < padded; i += 8) {
        const v8f centreWeight = groupWeights(i, wMinTotal, steep);
        const v8i better = centreWeight > best;
        best = better ? centreWeight : best;
        bestIndex = better ? int(i) + laneIndex : bestIndex;
    }
    ctx.wMinSum = wMinTotal.total();
    ctx.tiny = false;
    size_t dominant = 0;
    float wCentreMax = -1.0f;
    for (int l = 0; l < 8; ++l) {
        ctx.tiny = ctx.tiny || steep[l];
        if (best[l] > wCentreMax || (best[l] == wCentreMax && size_t(bestIndex[l]) < dominant)) {
            wCentreMax = best[l];
            dominant = size_t(bestIndex[l]);
        }
    }
    ctx.dominant = dominant;
}

CubeAnalysis::GroupDistance CubeAnalysis::groupDistance(const PC::Group& cg) const
{
    GroupDistance out;
    const v8f p[3] = {cf.x() - load8(cg.v[PC::Origin + 0]), cf.y() - load8(cg.v[PC::Origin + 1]),
                      cf.z() - load8(cg.v[PC::Origin + 2])};
    v8f q[3], v[3], out2 = zero;
    out.inside = load8(cg.v[PC::Box]) != zero;
    for (int k = 0; k < 3; ++k) {
        q[k] = load8(cg.v[PC::Axis + 3 * k + 0]) * p[0] + load8(cg.v[PC::Axis + 3 * k + 1]) * p[1] +
               load8(cg.v[PC::Axis + 3 * k + 2]) * p[2];
        const v8f d = outside(q[k], load8(cg.v[PC::Half + k]));
        out2 += d * d;
        v[k] = q[k] < zero ? -d : d;
        out.inside &= vabs(q[k]) + hf * load8(cg.v[PC::Reach + k]) <= load8(cg.v[PC::Half + k]);
    }
    const v8f d = out.d = vsqrt(out2);
    const v8i positive = d > zero;
    const v8f inv = positive ? one / d : zero;
    v8f gL1 = zero;
    for (int a = 0; a < 3; ++a) {
        out.g[a] =
            (load8(cg.v[PC::Axis + 3 * 0 + a]) * v[0] + load8(cg.v[PC::Axis + 3 * 1 + a]) * v[1] +
             load8(cg.v[PC::Axis + 3 * 2 + a]) * v[2]) *
            inv;
        gL1 += vabs(out.g[a]);
    }
    // d is convex (the distance to a convex set), so it lies above its tangent plane at the
    // centre: over the cube, d >= dc - h/2 |g|_1.
    out.dMin = positive ? vmax(zero, d - (0.5f * hf) * gL1) : zero;
    // And it lies below the distance to the centre's nearest point on the element, c - d g:
    // |x - c + d g|^2 = |x - c|^2 + 2 d g.(x - c) + d^2 <= 3 h^2/4 + h d |g|_1 + d^2 over the
    // cube (d + halfDiagonal only where g is along a diagonal).
    out.dMax = vmin(d + halfDiagonalF, vsqrt((d * d + (hf * d) * gL1) + (0.75f * hf * hf)));
    return out;
}

v8f CubeAnalysis::groupWeights(size_t i, WideSum& wMinTotal, v8i& steep)
{
    const PC::Group& cg = col.groups[i / 8];
    PairBounds::Group& pg = pb.groups[i / 8];
    const v8i live = load8(cg.v[PC::Live]) != zero;
    const GroupDistance gd = groupDistance(cg);
    const v8i inside = gd.inside;
    const v8f d = gd.d, dMin = gd.dMin, dMax = gd.dMax;
    const v8f* g = gd.g;
    const v8f rMin = offset + dMin, rMax = offset + (inside ? zero : dMax);
    store8(pg.v[C::Constant], inside ? one : zero);
    // Weights at the smallest and largest distance and at the centre.
    v8f wMax, wMin, wc;
    if (inverseSquare) {
        const v8f r0 = vmax(dMin, splat8(float(kTinyRadius) - offset)) + offset, r2 = d + offset;
        wMax = one / (r0 * r0);
        wMin = one / (rMax * rMax);
        wc = one / (r2 * r2);
    } else {
        for (int l = 0; l < 8; ++l) {
            const size_t j = std::min(i + l, n - 1); // padding lanes: any pair's values
            wMax[l] = float(warp.weightAt(j, std::max(double(dMin[l]), kTinyRadius - offset)));
            wMin[l] = float(warp.weightAt(j, double(rMax[l]) - offset));
            wc[l] = float(warp.weightAt(j, d[l]));
        }
    }
    store8(pg.v[C::WeightMax], wMax);
    wMinTotal.add(live ? wMin : zero);
    steep |= live & ((rMin < float(kTinyRadius)) | ~(wMax <= std::numeric_limits<float>::max()));
    // |grad w| and |Hess w| over the cube. Per axis a: |w_a| = b w / r |d_a| and
    // w_aa = w (b (b + 1) / r^2 (d_a)^2 - b / r d_aa). Hess d is positive semidefinite (d is
    // convex), has grad d as a null vector and eigenvalues at most 1 / d, so
    // 0 <= d_aa <= (1 - (d_a)^2) / d, and the two terms of w_aa, of opposite signs, bound it by the
    // larger. grad d is the unit vector from the element's nearest point; over the cube it turns
    // by at most |Hess d| halfDiagonal <= halfDiagonal / dMin, so
    // |g_a| - turn <= |d_a| <= |g_a| + turn. SlopeBound bounds sqrt(sum_a sup (w_a)^2),
    // CurveBound bounds sum_a sup |w_aa|; where the cube touches the element (dMin = 0) there is a
    // kink: CurveBound is infinite.
    const v8i apart = dMin > zero;
    const v8f invD = one / (apart ? dMin : one), invR = one / rMin;
    const v8f turn = vmin(one, halfDiagonalF * invD);
    const v8f bend = (b * (b + 1.0f)) * invR, curve = b * invD;
    // Along axis a, the slice s voxels from the cube's face nearest the element is s |g_a|
    // farther (d lies above its tangent plane at the centre), so with w ~ r^-b both sups over it
    // are at most (1 + kappa s)^-(b + 1) times those over the cube, kappa = |g_a| / rMin
    // (d / dMin grows at least as fast as r / rMin). Linear interpolation's error at x is the
    // integral of its Peano kernel G(x, s) against u''; with |u''(s)| <= M (1 + kappa s)^-3 its
    // largest value over x is, in closed form, h^2/8 M (2 / (q (q + 1)))^2 with
    // q = sqrt(1 + kappa h) (1 where kappa = 0): each axis's share carries that factor (1 for
    // Beier-Neely's law, whose exponent may be below 2).
    v8f axial = zero, curved = zero;
    for (int a = 0; a < 3; ++a) {
        const v8f hi = vmin(one, vabs(g[a]) + turn), lo = vmax(zero, vabs(g[a]) - turn);
        v8f share = one;
        if (inverseSquare) {
            const v8f kh = (hf * vabs(g[a])) * invR,
                      f = 2.0f / ((one + kh) + vsqrt(one + kh)); // q (q + 1) = q^2 + q
            share = f * f;
        }
        axial += (share * hi) * (share * hi);
        curved += share * vmax(bend * (hi * hi), curve * (one - lo * lo));
    }
    const v8f slopeBound = b * wMax * invR;
    const v8f first = apart ? slopeBound * vsqrt(axial) : slopeBound;
    const v8f second = apart ? wMax * invR * curved : infinity;
    store8(pg.v[C::SlopeBound], inside ? zero : first);
    store8(pg.v[C::CurveBound], inside ? zero : second);
    return live ? wc : splat8(-1.0f);
}

/// R_i = A_i - B at the centre, |R_i| over the cube on either side (|M_i - M_B| the slope), and
/// |rho| = |p - B| <= sum w_i |R_i| / W.
void CubeAnalysis::residuals(const std::vector<InverseWarp::Affine>& source,
                             const std::vector<InverseWarp::Affine>& target)
{
    bS = &source[ctx.dominant];
    bT = &target[ctx.dominant];
    slope = &columns.slope[ctx.dominant * padded];
    const Vec3f bc[2] = {Vec3f(bS->apply(centre)), Vec3f(bT->apply(centre))};
    WideSum rhoTotal;
    v8f residLargest = zero;
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        const v8i live = load8(cg.v[PC::Live]) != zero;
        v8f length2[2];
        for (int side = 0; side < 2; ++side) {
            length2[side] = zero;
            for (int a = 0; a < 3; ++a) {
                const v8f r = load8(cg.v[PC::Affine + 12 * side + 3 * 0 + a]) * cf.x() +
                              load8(cg.v[PC::Affine + 12 * side + 3 * 1 + a]) * cf.y() +
                              load8(cg.v[PC::Affine + 12 * side + 3 * 2 + a]) * cf.z() +
                              load8(cg.v[PC::Affine + 12 * side + 3 * 3 + a]) - bc[side][a];
                store8(pg.v[(side == 0 ? C::ResidualS0 : C::ResidualT0) + a], r);
                length2[side] += r * r;
            }
        }
        const v8f resid = vsqrt(vmax(length2[0], length2[1])) + load8(&slope[i]) * halfDiagonalF;
        store8(pg.v[C::ResidualMax], resid);
        const v8f wMax = live ? load8(pg.v[C::WeightMax]) : zero, residLive = live ? resid : zero;
        rhoTotal.lo += lowHalf(wMax) * lowHalf(residLive); // products of floats, exact in double
        rhoTotal.hi += highHalf(wMax) * highHalf(residLive);
        residLargest = vmax(residLargest, residLive);
    }
    const double rhoSum = rhoTotal.total();
    double residMax = 0.0;
    for (int l = 0; l < 8; ++l) residMax = std::max(residMax, double(residLargest[l]));
    ctx.rhoMax = std::min(residMax, rhoSum / ctx.wMinSum);
}

/// Each far pair's share of the bound; one pair is its own affine map (R = 0, rho = 0). With
/// every pair far, the interpolated W is a convex combination of the corners' W.
void CubeAnalysis::shares()
{
    hh8 = float(kBoundScale * h * h / 8.0);
    rhoMaxF = float(ctx.rhoMax);
    const v8f none = n == 1 ? one : zero;
    WideSum shareTotal, curveSum;
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        const v8f w1 = load8(pg.v[C::SlopeBound]), w2 = load8(pg.v[C::CurveBound]);
        const v8i skip =
            (load8(pg.v[C::Constant]) != zero) | (none != zero) | (load8(cg.v[PC::Live]) == zero);
        const v8f share = skip             ? zero
                          : w2 == infinity ? infinity
                                           : hh8 * ((load8(pg.v[C::ResidualMax]) + rhoMaxF) * w2 +
                                                    2.0f * load8(&slope[i]) * w1);
        const v8f curve = skip ? zero : hh8 * w2;
        store8(pg.v[C::CurveShare], curve);
        store8(pg.v[C::Share], share);
        shareTotal.add(share);
        curveSum.add(curve);
    }
    curveTotal = curveSum.total();
    ctx.boundAllFar = errorBound(ctx.wMinSum, shareTotal.total(), curveTotal, ctx.wCornerMin);
}

/// The corners' residuals rho_k = p_k - B(x_k): their box on each side (the domain test uses it
/// too), its centre rho_0 and largest distance r. Corners 0-3 (z = 0) and 4-7 (z = h), 4 lanes
/// each; B(x) as Affine::apply computes it.
void CubeAnalysis::cornerResiduals(const LatticePoint* const corners[8])
{
    const v4d cornerX = o.x() + v4d{0, h, 0, h}, cornerY = o.y() + v4d{0, 0, h, h};
    const v4d cornerZ[2] = {splat(o.z()), splat(o.z() + h)};
    v4d inverseW[2]; // 1 / w at the corners
    for (int m = 0; m < 2; ++m) {
        for (int l = 0; l < 4; ++l) inverseW[m][l] = corners[4 * m + l]->w;
        inverseW[m] = 1.0 / inverseW[m];
    }
    for (int side = 0; side < 2; ++side) {
        const InverseWarp::Affine& bA = side == 0 ? *bS : *bT;
        v4d rho[3][2];
        for (int a = 0; a < 3; ++a)
            for (int m = 0; m < 2; ++m) {
                const v4d bx = ((bA.col[0][a] * cornerX + bA.col[1][a] * cornerY) +
                                bA.col[2][a] * cornerZ[m]) +
                               bA.offset[a];
                store4(&ctx.cornerB[side][a][4 * m], bx);
                v4d sum; // S or T
                for (int l = 0; l < 4; ++l) {
                    const LatticePoint& q = *corners[4 * m + l];
                    sum[l] = (side == 0 ? q.s : q.t)[a];
                }
                rho[a][m] = sum * inverseW[m] - bx; // the exact point S / W less B
            }
        Vec3d lo, hi;
        for (int a = 0; a < 3; ++a) {
            const v4d l = vmin(rho[a][0], rho[a][1]), u = vmax(rho[a][0], rho[a][1]);
            lo[a] = std::min(std::min(l[0], l[1]), std::min(l[2], l[3]));
            hi[a] = std::max(std::max(u[0], u[1]), std::max(u[2], u[3]));
        }
        ctx.rhoLo[side] = lo;
        ctx.rhoHi[side] = hi;
        const Vec3d mid = ctx.rhoMid[side] = 0.5 * (lo + hi);
        v4d r2 = splat(0.0);
        for (int m = 0; m < 2; ++m) {
            const v4d dx = rho[0][m] - mid.x(), dy = rho[1][m] - mid.y(), dz = rho[2][m] - mid.z();
            r2 = vmax(r2, (dx * dx + dy * dy) + dz * dz);
        }
        radius[side] = std::sqrt(std::max(std::max(r2[0], r2[1]), std::max(r2[2], r2[3])));
    }
}

/// A second, tighter pass where the all-far bound is finite. A far pair's share of the error is
/// (R_i(c) - rho(x)) (I[w_i] - w_i) + D_i (I[w_i (x - c)] - w_i (x - c)), c the centre and
/// D_i = M_i - M_B, so |R_i(c)| + |rho| above may be replaced by |R_i(c) - rho(x)|. The all-far
/// interpolant's rho lies in the hull of the corners' rho_k and within boundAllFar of the true
/// rho: |R_i(c) - rho(x)| <= |R_i(c) - rho_0| + r + boundAllFar, with rho_0 the centre of the
/// corners' box and r its largest distance to a corner (each side).
void CubeAnalysis::tighten()
{
    const Vec3f mid[2] = {Vec3f(ctx.rhoMid[0]), Vec3f(ctx.rhoMid[1])};
    const float boundAllFar = float(ctx.boundAllFar), radiusS = float(radius[0]),
                radiusT = float(radius[1]);
    WideSum tightTotal;
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        v8f length2[2] = {zero, zero};
        for (int a = 0; a < 3; ++a) {
            const v8f ds = load8(pg.v[C::ResidualS0 + a]) - mid[0][a],
                      dt = load8(pg.v[C::ResidualT0 + a]) - mid[1][a];
            length2[0] += ds * ds;
            length2[1] += dt * dt;
        }
        const v8f w1 = load8(pg.v[C::SlopeBound]), w2 = load8(pg.v[C::CurveBound]),
                  share = load8(pg.v[C::Share]);
        const v8f apart = vmax(vsqrt(length2[0]) + radiusS, vsqrt(length2[1]) + radiusT) +
                          load8(&slope[i]) * halfDiagonalF + boundAllFar;
        const v8i tighter = (share != infinity) & (load8(pg.v[C::Constant]) == zero) &
                            (apart < load8(pg.v[C::ResidualMax]) + rhoMaxF);
        const v8f tightShare = tighter ? hh8 * (apart * w2 + 2.0f * load8(&slope[i]) * w1) : share;
        store8(pg.v[C::Share], tightShare);
        // Padding lanes hold no pair.
        tightTotal.add(load8(cg.v[PC::Live]) != zero ? tightShare : zero);
    }
    ctx.boundAllFar = std::min(
        ctx.boundAllFar, errorBound(ctx.wMinSum, tightTotal.total(), curveTotal, ctx.wCornerMin));
}

} // namespace

VOLMORPH_ALWAYS_INLINE inline void AdaptiveWarp::analyzeBody(WarpContext& ctx,
                                                             const LatticePoint* const corners[8],
                                                             const Coord& origin, int size) const
{
    CubeAnalysis cube(ctx, origin, size, mWarp, *mColumns);
    cube.corners(corners);
    cube.weights();
    cube.residuals(mSource, mTarget);
    cube.shares();
    if (!ctx.cornersOk) return;
    cube.cornerResiduals(corners);
    if (!std::isfinite(ctx.boundAllFar) || mWarp.pairCount() == 1) return;
    cube.tighten();
}

#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 void AdaptiveWarp::analyzeAvx2(WarpContext& ctx, const LatticePoint* const corners[8],
                                             const Coord& origin, int size) const
{
    analyzeBody(ctx, corners, origin, size);
}
VOLMORPH_AVX512 void AdaptiveWarp::analyzeAvx512(WarpContext& ctx,
                                                 const LatticePoint* const corners[8],
                                                 const Coord& origin, int size) const
{
    analyzeBody(ctx, corners, origin, size);
}
#endif

void AdaptiveWarp::analyzeBaseline(WarpContext& ctx, const LatticePoint* const corners[8],
                                   const Coord& origin, int size) const
{
    analyzeBody(ctx, corners, origin, size);
}

void AdaptiveWarp::analyze(WarpContext& ctx, const LatticePoint* const corners[8],
                           const Coord& origin, int size) const
{
    (this->*pickBuild(mBuild, VOLMORPH_BUILDS(&AdaptiveWarp::analyze)))(ctx, corners, origin, size);
}

double AdaptiveWarp::selectNear(WarpContext& ctx, size_t& nearCount) const
{
    // Largest share first, until the far pairs' bound is within the tolerance: the far sums are
    // the totals less the near pairs' shares (infinite shares, kinks, counted apart).
    const size_t n = mWarp.pairCount();
    // The shares and curve shares, in pair order (from their groups).
    std::vector<float>& share = ctx.shareList;
    std::vector<float>& curve = ctx.curveList;
    share.resize(n);
    curve.resize(n);
    for (size_t i = 0; i < n; ++i) {
        share[i] = ctx.bounds.get(PairBounds::Share, i);
        curve[i] = ctx.bounds.get(PairBounds::CurveShare, i);
    }
    ctx.isNear.assign(n, 0);
    double shares = 0.0, curves = 0.0;
    size_t kinks = 0;
    for (size_t i = 0; i < n; ++i) {
        if (std::isfinite(share[i])) {
            shares += share[i];
            curves += curve[i];
        } else {
            ++kinks;
        }
    }
    nearCount = 0;
    double b = ctx.boundAllFar;
    while (b > mTolerance && nearCount < n) {
        size_t best = n;
        for (size_t i = 0; i < n; ++i)
            if (!ctx.isNear[i] && (best == n || share[i] > share[best])) best = i;
        ctx.isNear[best] = 1;
        ++nearCount;
        if (std::isfinite(share[best])) {
            shares = std::max(0.0, shares - share[best]);
            curves = std::max(0.0, curves - curve[best]);
        } else {
            --kinks;
        }
        b = kinks > 0 ? std::numeric_limits<double>::infinity()
                      : errorBound(ctx.wMinSum, shares, curves, 0.0);
    }
    ctx.nearList.clear();
    for (size_t k = 0; nearCount > 0 && k < n; ++k)
        if (ctx.isNear[mByType[k]]) ctx.nearList.push_back(mByType[k]);
    return nearCount == n ? 0.0 : b; // every pair near: exact at every voxel but for rounding
}

} // namespace volmorph::detail
