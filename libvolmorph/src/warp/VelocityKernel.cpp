#include "warp/VelocityKernel.h"

#include "warp/adaptive/Simd.h"

#include <algorithm>
#include <cmath>

namespace volmorph::detail {

VelocityKernel::VelocityKernel(const InverseWarp& warp, double exactWithin, KernelBuild limit)
    : mWarp(warp), mReference(0.0), mExactWithin(exactWithin),
      mBuild(KernelBuild(std::min(int(bestKernelBuild()), int(limit))))
{
    const size_t n = warp.pairCount();
    for (size_t i = 0; i < n; ++i) mReference += warp.interpolated(i).origin / double(n);
    mGroups.assign((n + 7) / 8, Group{});
    for (size_t i = 0; i < n; ++i) {
        auto set = [&](int c, double v) { mGroups[i / 8].v[c][i % 8] = float(v); };
        const Feature& e = warp.interpolated(i);
        const InverseWarp::Motion m = warp.motion(i);
        const InverseWarp::Affine maps[2] = {warp.sourceAffine(i), warp.targetAffine(i)};
        const Vec3d* axes[3] = {&e.x, &e.y, &e.z};
        for (int k = 0; k < 3; ++k) {
            const bool extends = k < e.extendedAxes();
            set(Group::Origin + k, e.origin[k] - mReference[k]);
            for (int a = 0; a < 3; ++a) set(Group::Axis + 3 * k + a, (*axes[k])[a]);
            set(Group::Half + k, extends ? 0.5 * e.scale[k] : 0.0);
            set(Group::HalfRate + k, extends ? 0.5 * m.scaleRate[k] : 0.0);
            set(Group::Stretch + k, e.scale[k] != 0.0 ? m.scaleRate[k] / e.scale[k] : 0.0);
            set(Group::OriginRate + k, m.originRate[k]);
            set(Group::Omega + k, m.omega[k]);
        }
        set(Group::LengthRate, m.lengthWeightRate);
        set(Group::Live, 1.0);
        for (int side = 0; side < 2; ++side) {
            const Vec3d offset = maps[side].apply(mReference) - mReference;
            for (int a = 0; a < 3; ++a) {
                for (int c = 0; c < 3; ++c) {
                    set(Group::Affine + 12 * side + 3 * c + a, maps[side].col[c][a]);
                    set(Group::To + 9 * side + 3 * c + a,
                        (side == 0 ? m.toSource : m.toTarget)[c][a]);
                }
                set(Group::Affine + 12 * side + 9 + a, offset[a]);
            }
        }
    }
}

namespace {

/// The running sums (the header's W, Q, G and each side's P, R, M), a lane per pair, padded to
/// whole blocks of 8 for the transposed reduction.
struct Sums {
    enum { W = 0, Q = 1, Grad = 2, Side = 5, P = 0, R = 3, M = 6, PerSide = 15, Used = 35 };
    enum { Count = 40 };
    v8f v[Count];
    bool first = true; ///< the first group's terms are stored, not added: nothing to clear

    VOLMORPH_ALWAYS_INLINE Sums()
    {
        for (int i = Used; i < Count; ++i) v[i] = v8f{};
    }

    VOLMORPH_ALWAYS_INLINE void add(int i, v8f x) { v[i] = first ? x : v[i] + x; }

    /// Every sum's lane total, summed in the same order in every build:
    /// ((l0 + l1) + (l2 + l3)) + ((l4 + l5) + (l6 + l7)).
    VOLMORPH_ALWAYS_INLINE void totals(float out[Count]) const
    {
        // For each block of 8 sums: pairs of lanes (a01 b01 a23 b23 ...), then fours, then eights.
        auto twos = [](v8f a, v8f b) {
            return __builtin_shufflevector(a, b, 0, 8, 2, 10, 4, 12, 6, 14) +
                   __builtin_shufflevector(a, b, 1, 9, 3, 11, 5, 13, 7, 15);
        };
        auto fours = [](v8f a, v8f b) {
            return __builtin_shufflevector(a, b, 0, 1, 8, 9, 4, 5, 12, 13) +
                   __builtin_shufflevector(a, b, 2, 3, 10, 11, 6, 7, 14, 15);
        };
        for (int i = 0; i < Count; i += 8) {
            const v8f* x = v + i;
            // a0-3 b0-3 c0-3 d0-3, a4-7 b4-7 c4-7 d4-7; the same for e-h.
            const v8f abcd = fours(twos(x[0], x[1]), twos(x[2], x[3]));
            const v8f efgh = fours(twos(x[4], x[5]), twos(x[6], x[7]));
            store8(out + i, __builtin_shufflevector(abcd, efgh, 0, 1, 2, 3, 8, 9, 10, 11) +
                                __builtin_shufflevector(abcd, efgh, 4, 5, 6, 7, 12, 13, 14, 15));
        }
    }
};

/// One group's pairs at a point: the weights and their gradients and rates, and the frame
/// coordinates and their rates (WarpDerivatives.cpp's names), a lane per pair.
struct PairTerms {
    v8f w, wRate, gw[3], q[3], qRate[3];
    v8i tooNear; ///< live lanes whose d + offset is under the kernel's `near`

    /// y: the point relative to the kernel's reference; firstPair: the group's first pair.
    VOLMORPH_ALWAYS_INLINE PairTerms(const VelocityKernel::Group& g, const float y[3],
                                     const InverseWarp& warp, size_t firstPair, float near)
    {
        using G = VelocityKernel::Group;
        const v8f zero = splat8(0.0f), one = splat8(1.0f);
        auto col = [&g](int c) { return load8(g.v[c]); };
        const v8f dx[3] = {y[0] - col(G::Origin), y[1] - col(G::Origin + 1),
                           y[2] - col(G::Origin + 2)};
        // u = (p' - c') x omega - dc'/dt, in world axes; q and its rate in the element's frame.
        const v8f om[3] = {col(G::Omega), col(G::Omega + 1), col(G::Omega + 2)};
        const v8f u[3] = {dx[1] * om[2] - dx[2] * om[1] - col(G::OriginRate),
                          dx[2] * om[0] - dx[0] * om[2] - col(G::OriginRate + 1),
                          dx[0] * om[1] - dx[1] * om[0] - col(G::OriginRate + 2)};
        v8f off[3], d2 = zero;
        for (int k = 0; k < 3; ++k) {
            const v8f a0 = col(G::Axis + 3 * k), a1 = col(G::Axis + 3 * k + 1),
                      a2 = col(G::Axis + 3 * k + 2);
            q[k] = a0 * dx[0] + a1 * dx[1] + a2 * dx[2];
            qRate[k] = a0 * u[0] + a1 * u[1] + a2 * u[2];
            const v8f h = col(G::Half + k);
            off[k] = q[k] - vmin(vmax(q[k], -h), h);
            d2 += off[k] * off[k];
        }
        const v8f dist = vsqrt(d2), r = dist + float(warp.weightOffset());
        const v8i live = col(G::Live) != zero;
        tooNear = live & (r < near);
        const v8f invD = dist > zero ? one / (dist > zero ? dist : one) : zero;
        const v8f invR = one / (live ? r : one);
        v8f dRate = zero, gn[3];
        for (int k = 0; k < 3; ++k) {
            gn[k] = off[k] * invD; // the distance's gradient in the frame
            dRate += gn[k] * qRate[k] - vabs(gn[k]) * col(G::HalfRate + k);
        }
        if (warp.weighting() == Weighting::InverseSquare) {
            w = invR * invR;
        } else {
            for (int l = 0; l < 8; ++l)
                w[l] = float(
                    warp.weightAt(std::min(firstPair + l, warp.pairCount() - 1), double(dist[l])));
        }
        w = live ? w : zero;
        const v8f dwdd = -float(warp.weightExponent()) * w * invR;
        wRate = dwdd * dRate + w * col(G::LengthRate);
        for (int a = 0; a < 3; ++a) // grad w_i, world axes
            gw[a] = dwdd * (col(G::Axis + a) * gn[0] + col(G::Axis + 3 + a) * gn[1] +
                            col(G::Axis + 6 + a) * gn[2]);
    }

    /// Adds the group's terms to `sums`: both sides' maps at y.
    VOLMORPH_ALWAYS_INLINE void addTo(Sums& sums, const VelocityKernel::Group& g,
                                      const float y[3]) const
    {
        using G = VelocityKernel::Group;
        auto col = [&g](int c) { return load8(g.v[c]); };
        sums.add(Sums::W, w);
        sums.add(Sums::Q, wRate);
        for (int a = 0; a < 3; ++a) sums.add(Sums::Grad + a, gw[a]);
        const v8f qs[3] = {qRate[0] - q[0] * col(G::Stretch), qRate[1] - q[1] * col(G::Stretch + 1),
                           qRate[2] - q[2] * col(G::Stretch + 2)};
        for (int s = 0; s < 2; ++s) {
            const int A = G::Affine + 12 * s, T = G::To + 9 * s;
            const int side = Sums::Side + Sums::PerSide * s;
            for (int a = 0; a < 3; ++a) {
                const v8f p = col(A + a) * y[0] + col(A + 3 + a) * y[1] + col(A + 6 + a) * y[2] +
                              col(A + 9 + a) - y[a];
                const v8f rate =
                    col(T + a) * qs[0] + col(T + 3 + a) * qs[1] + col(T + 6 + a) * qs[2];
                sums.add(side + Sums::P + a, w * p);
                sums.add(side + Sums::R + a, w * rate + wRate * p);
                for (int b = 0; b < 3; ++b)
                    sums.add(side + Sums::M + 3 * a + b, w * col(A + 3 * b + a) + p * gw[b]);
            }
        }
        sums.first = false;
    }
};

/// Both sides' derivatives from the sums' totals (the header's quotient rule); false without a
/// finite positive weight.
VOLMORPH_ALWAYS_INLINE inline bool quotientRule(const Sums& sums, InverseWarp::Derivatives d[2])
{
    float total[Sums::Count];
    sums.totals(total);
    const double sumW = total[Sums::W];
    if (!std::isfinite(sumW) || !(sumW > 0.0)) return false;
    const double sumRate = total[Sums::Q], invW = 1.0 / sumW;
    const float* grad = total + Sums::Grad;
    for (int s = 0; s < 2; ++s) {
        const float* side = total + Sums::Side + Sums::PerSide * s;
        for (int a = 0; a < 3; ++a) {
            const double mean = side[Sums::P + a] * invW;
            for (int b = 0; b < 3; ++b)
                d[s].jacobian(a, b) = (side[Sums::M + 3 * a + b] - mean * grad[b]) * invW;
            d[s].rate[a] = (side[Sums::R + a] - mean * sumRate) * invW;
        }
    }
    return true;
}

} // namespace

VOLMORPH_ALWAYS_INLINE inline bool VelocityKernel::sumsBody(const Vec3d& x,
                                                            InverseWarp::Derivatives d[2]) const
{
    const float near = float(std::max(mExactWithin, InverseWarp::kOnElement));
    const float y[3] = {float(x.x() - mReference.x()), float(x.y() - mReference.y()),
                        float(x.z() - mReference.z())};
    Sums sums;
    for (size_t gi = 0; gi < mGroups.size(); ++gi) {
        const PairTerms terms(mGroups[gi], y, mWarp, 8 * gi, near);
        for (int l = 0; l < 8; ++l)
            if (terms.tooNear[l]) return false;
        terms.addTo(sums, mGroups[gi], y);
    }
    return quotientRule(sums, d);
}

#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 bool VelocityKernel::sumsAvx2(const Vec3d& p, InverseWarp::Derivatives d[2]) const
{
    return sumsBody(p, d);
}
VOLMORPH_AVX512 bool VelocityKernel::sumsAvx512(const Vec3d& p, InverseWarp::Derivatives d[2]) const
{
    return sumsBody(p, d);
}
#endif

bool VelocityKernel::sumsBaseline(const Vec3d& p, InverseWarp::Derivatives d[2]) const
{
    return sumsBody(p, d);
}

bool VelocityKernel::sums(const Vec3d& p, InverseWarp::Derivatives d[2]) const
{
    return (this->*pickBuild(mBuild, VOLMORPH_BUILDS(&VelocityKernel::sums)))(p, d);
}

void VelocityKernel::derivatives(const Vec3d& p, InverseWarp::Derivatives& source,
                                 InverseWarp::Derivatives& target) const
{
    InverseWarp::Derivatives d[2];
    if (mGroups.empty() || !sums(p, d)) return mWarp.derivatives(p, source, target);
    source = d[0];
    target = d[1];
}

} // namespace volmorph::detail
