#include "warp/adaptive/LatticeSums.h"

#include "warp/adaptive/PairColumns.h"
#include "warp/adaptive/Simd.h"

#include <cmath>

namespace volmorph::detail {

/// The exact warp's unnormalized sums W = sum w_i, S = sum w_i A_S,i, T = sum w_i A_T,i at x (so
/// that S / W and T / W are InverseWarp::map's points), over the pairs' columns, 4 at a time.
VOLMORPH_ALWAYS_INLINE inline bool AdaptiveWarp::exactSumsBody(const Vec3d& x,
                                                               LatticePoint& out) const
{
    const size_t n = mWarp.pairCount();
    const PairColumns<double>& col = mColumns->exact;
    const double offset = mWarp.weightOffset();
    const bool inverseSquare = mWarp.weighting() == Weighting::InverseSquare;
    const v4d zero = splat(0.0), one = splat(1.0);
    v4d W = zero, S[3] = {zero, zero, zero}, T[3] = {zero, zero, zero};
    v4l onElement = v4l{0, 0, 0, 0};
    using PC = PairColumns<double>;
    for (size_t i = 0; i < col.padded; i += 4) {
        const PC::Group& cg = col.groups[i / 4];
        const v4d p[3] = {x.x() - load4(cg.v[PC::Origin + 0]), x.y() - load4(cg.v[PC::Origin + 1]),
                          x.z() - load4(cg.v[PC::Origin + 2])};
        v4d out2 = zero;
        for (int k = 0; k < 3; ++k) {
            const v4d q = load4(cg.v[PC::Axis + 3 * k + 0]) * p[0] +
                          load4(cg.v[PC::Axis + 3 * k + 1]) * p[1] +
                          load4(cg.v[PC::Axis + 3 * k + 2]) * p[2];
            const v4d d = outside(q, load4(cg.v[PC::Half + k]));
            out2 += d * d;
        }
        const v4d d = vsqrt(out2), r = d + offset;
        const v4l live = load4(cg.v[PC::Live]) != zero;
        onElement |= live & (r < InverseWarp::kOnElement);
        v4d w;
        if (inverseSquare) {
            w = one / (r * r);
        } else {
            for (int l = 0; l < 4; ++l) w[l] = mWarp.weightAt(std::min(i + l, n - 1), d[l]);
        }
        w = live ? w : zero;
        W += w;
        for (int a = 0; a < 3; ++a) {
            S[a] += w * (load4(cg.v[PC::Affine + 3 * 0 + a]) * x.x() +
                         load4(cg.v[PC::Affine + 3 * 1 + a]) * x.y() +
                         load4(cg.v[PC::Affine + 3 * 2 + a]) * x.z() +
                         load4(cg.v[PC::Affine + 3 * 3 + a]));
            T[a] += w * (load4(cg.v[PC::Affine + 12 + 3 * 0 + a]) * x.x() +
                         load4(cg.v[PC::Affine + 12 + 3 * 1 + a]) * x.y() +
                         load4(cg.v[PC::Affine + 12 + 3 * 2 + a]) * x.z() +
                         load4(cg.v[PC::Affine + 12 + 3 * 3 + a]));
        }
    }
    auto total = [](v4d v) { return (v[0] + v[1]) + (v[2] + v[3]); };
    out.w = total(W);
    out.s = Vec3d(total(S[0]), total(S[1]), total(S[2]));
    out.t = Vec3d(total(T[0]), total(T[1]), total(T[2]));
    const bool on = onElement[0] || onElement[1] || onElement[2] || onElement[3];
    return !on && std::isfinite(out.w) && out.w > 0.0;
}

#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 bool AdaptiveWarp::exactSumsAvx2(const Vec3d& x, LatticePoint& out) const
{
    return exactSumsBody(x, out);
}
VOLMORPH_AVX512 bool AdaptiveWarp::exactSumsAvx512(const Vec3d& x, LatticePoint& out) const
{
    return exactSumsBody(x, out);
}
#endif

bool AdaptiveWarp::exactSumsBaseline(const Vec3d& x, LatticePoint& out) const
{
    return exactSumsBody(x, out);
}

bool AdaptiveWarp::exactSums(const Vec3d& x, LatticePoint& out) const
{
    return (this->*pickBuild(mBuild, VOLMORPH_BUILDS(&AdaptiveWarp::exactSums)))(x, out);
}

} // namespace volmorph::detail
