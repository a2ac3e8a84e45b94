#include "warp/VelocityKernel.h"

#include "warp/adaptive/Simd.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::detail {

VelocityKernel::VelocityKernel(const InverseWarp& warp, double exactWithin, KernelBuild limit)
    : mWarp(warp), mReference(0.0), mExactWithin(exactWithin),
      mBuild(KernelBuild(std::min(int(bestKernelBuild()), int(limit))))
{
    const size_t n = warp.pairCount();
    for (size_t i = 0; i < n; ++i) mReference += warp.interpolated(i).origin / double(n);
    mPairs.resize(n);
    for (size_t i = 0; i < n; ++i) {
        auto set = [&](int c, double v) { mPairs[i].v[c] = float(v); };
        const Feature& e = warp.interpolated(i);
        const InverseWarp::Motion m = warp.motion(i);
        const InverseWarp::Affine maps[2] = {warp.sourceAffine(i), warp.targetAffine(i)};
        const Vec3d* axes[3] = {&e.x, &e.y, &e.z};
        for (int k = 0; k < 3; ++k) {
            const bool extends = k < e.extendedAxes();
            set(Pair::Origin + k, e.origin[k] - mReference[k]);
            for (int a = 0; a < 3; ++a) set(Pair::Axis + 3 * k + a, (*axes[k])[a]);
            set(Pair::Half + k, extends ? 0.5 * e.scale[k] : 0.0);
            set(Pair::HalfRate + k, extends ? 0.5 * m.scaleRate[k] : 0.0);
            set(Pair::Stretch + k, e.scale[k] != 0.0 ? m.scaleRate[k] / e.scale[k] : 0.0);
            set(Pair::OriginRate + k, m.originRate[k]);
            set(Pair::Omega + k, m.omega[k]);
        }
        set(Pair::LengthRate, m.lengthWeightRate);
        for (int side = 0; side < 2; ++side) {
            const Vec3d offset = maps[side].apply(mReference) - mReference;
            for (int a = 0; a < 3; ++a) {
                for (int c = 0; c < 3; ++c) {
                    set(Pair::Affine + 12 * side + 3 * c + a, maps[side].col[c][a]);
                    set(Pair::To + 9 * side + 3 * c + a,
                        (side == 0 ? m.toSource : m.toTarget)[c][a]);
                }
                set(Pair::Affine + 12 * side + 9 + a, offset[a]);
            }
        }
    }
}

namespace {

/// The running sums (the header's W, Q, G and each side's P, R, M), a lane per point.
struct Sums {
    enum { W = 0, Q = 1, Grad = 2, Side = 5, P = 0, R = 3, M = 6, PerSide = 15, Count = 35 };
    v8f v[Count];
};

/// One pair's terms at 8 points (WarpDerivatives.cpp's names), a lane per point.
struct PairTerms {
    v8f w, wRate, gw[3], q[3], qRate[3];
    v8i tooNear; ///< lanes whose d + offset is under `near`

    /// y: the points relative to the kernel's reference; i: the pair's index.
    VOLMORPH_ALWAYS_INLINE PairTerms(const VelocityKernel::Pair& pair, const v8f y[3],
                                     const InverseWarp& warp, size_t i, float near)
    {
        using P = VelocityKernel::Pair;
        const float* c = pair.v;
        const v8f zero = splat8(0.0f), one = splat8(1.0f);
        const v8f dx[3] = {y[0] - c[P::Origin], y[1] - c[P::Origin + 1], y[2] - c[P::Origin + 2]};
        // u = (p' - c') x omega - dc'/dt, in world axes; q and its rate in the element's frame.
        const float* om = c + P::Omega;
        const v8f u[3] = {dx[1] * om[2] - dx[2] * om[1] - c[P::OriginRate],
                          dx[2] * om[0] - dx[0] * om[2] - c[P::OriginRate + 1],
                          dx[0] * om[1] - dx[1] * om[0] - c[P::OriginRate + 2]};
        v8f off[3], d2 = zero;
        for (int k = 0; k < 3; ++k) {
            const float* axis = c + P::Axis + 3 * k;
            q[k] = axis[0] * dx[0] + axis[1] * dx[1] + axis[2] * dx[2];
            qRate[k] = axis[0] * u[0] + axis[1] * u[1] + axis[2] * u[2];
            const v8f h = splat8(c[P::Half + k]);
            off[k] = q[k] - vmin(vmax(q[k], -h), h);
            d2 += off[k] * off[k];
        }
        const v8f dist = vsqrt(d2), r = dist + float(warp.weightOffset());
        tooNear = r < near;
        const v8f invD = dist > zero ? one / (dist > zero ? dist : one) : zero;
        const v8f invR = one / (tooNear ? one : r);
        v8f dRate = zero, gn[3];
        for (int k = 0; k < 3; ++k) {
            gn[k] = off[k] * invD; // the distance's gradient in the frame
            dRate += gn[k] * qRate[k] - vabs(gn[k]) * c[P::HalfRate + k];
        }
        if (warp.weighting() == Weighting::InverseSquare) {
            w = invR * invR;
        } else {
            for (int l = 0; l < 8; ++l) w[l] = float(warp.weightAt(i, double(dist[l])));
        }
        const v8f dwdd = -float(warp.weightExponent()) * w * invR;
        wRate = dwdd * dRate + w * c[P::LengthRate];
        for (int a = 0; a < 3; ++a) // grad w_i, world axes
            gw[a] = dwdd * (c[P::Axis + a] * gn[0] + c[P::Axis + 3 + a] * gn[1] +
                            c[P::Axis + 6 + a] * gn[2]);
    }

    /// Adds the pair's terms to `sums`: both sides' maps at y.
    VOLMORPH_ALWAYS_INLINE void addTo(Sums& sums, const VelocityKernel::Pair& pair,
                                      const v8f y[3]) const
    {
        using P = VelocityKernel::Pair;
        const float* c = pair.v;
        v8f* S = sums.v;
        S[Sums::W] += w;
        S[Sums::Q] += wRate;
        for (int a = 0; a < 3; ++a) S[Sums::Grad + a] += gw[a];
        const v8f qs[3] = {qRate[0] - q[0] * c[P::Stretch], qRate[1] - q[1] * c[P::Stretch + 1],
                           qRate[2] - q[2] * c[P::Stretch + 2]};
        for (int s = 0; s < 2; ++s) {
            const float* A = c + P::Affine + 12 * s;
            const float* T = c + P::To + 9 * s;
            v8f* side = S + Sums::Side + Sums::PerSide * s;
            for (int a = 0; a < 3; ++a) {
                const v8f p = A[a] * y[0] + A[3 + a] * y[1] + A[6 + a] * y[2] + A[9 + a] - y[a];
                const v8f rate = T[a] * qs[0] + T[3 + a] * qs[1] + T[6 + a] * qs[2];
                side[Sums::P + a] += w * p;
                side[Sums::R + a] += w * rate + wRate * p;
                for (int b = 0; b < 3; ++b)
                    side[Sums::M + 3 * a + b] += w * A[3 * b + a] + p * gw[b];
            }
        }
    }
};

/// Both sides' velocities at each lane from the sums: the header's quotient rule, then
/// v = -J^-1 dW/dt by the columns' cross products (as InverseWarp::velocity); `fold` gets the lanes
/// where J is singular (v = 0). Returns the lanes without a finite positive weight.
VOLMORPH_ALWAYS_INLINE inline v8i quotientRule(const Sums& sums, Vec3d* v[2], v8i fold[2])
{
    const v8f* S = sums.v;
    const v8f W = S[Sums::W], zero = splat8(0.0f), one = splat8(1.0f);
    const v8i bad = !(W > 0.0f && W < std::numeric_limits<float>::infinity());
    const v8f invW = one / (bad ? one : W);
    for (int s = 0; s < 2; ++s) {
        const v8f* side = S + Sums::Side + Sums::PerSide * s;
        v8f j[3][3], rate[3];
        for (int a = 0; a < 3; ++a) {
            const v8f mean = side[Sums::P + a] * invW;
            for (int b = 0; b < 3; ++b)
                j[a][b] = (side[Sums::M + 3 * a + b] - mean * S[Sums::Grad + b]) * invW;
            rate[a] = (side[Sums::R + a] - mean * S[Sums::Q]) * invW;
        }
        // The rows of adj(J) are c1 x c2, c2 x c0, c0 x c1 (c the columns).
        auto cross = [&j](int x, int y, int a) { // component a of column x cross column y
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            return j[b][x] * j[c][y] - j[c][x] * j[b][y];
        };
        v8f adj[3][3];
        for (int r = 0; r < 3; ++r)
            for (int a = 0; a < 3; ++a) adj[r][a] = cross((r + 1) % 3, (r + 2) % 3, a);
        const v8f det = j[0][0] * adj[0][0] + j[1][0] * adj[0][1] + j[2][0] * adj[0][2];
        fold[s] = !(vabs(det) > 1e-12f);
        const v8f scale = fold[s] ? zero : -one / (fold[s] ? one : det);
        for (int r = 0; r < 3; ++r) {
            const v8f out =
                (adj[r][0] * rate[0] + adj[r][1] * rate[1] + adj[r][2] * rate[2]) * scale;
            for (int l = 0; l < 8; ++l) v[s][l][r] = out[l];
        }
    }
    return bad;
}

/// Every pair's terms at the 8 points y (relative to the reference) into `sums`; returns the lanes
/// too near an element for single precision.
VOLMORPH_ALWAYS_INLINE inline v8i addPairs(const std::vector<VelocityKernel::Pair>& pairs,
                                           const InverseWarp& warp, const v8f y[3], float near,
                                           Sums& sums)
{
    for (v8f& v : sums.v) v = v8f{};
    v8i tooNear = v8i{};
    for (size_t i = 0; i < pairs.size(); ++i) {
        const PairTerms terms(pairs[i], y, warp, i, near);
        tooNear |= terms.tooNear;
        terms.addTo(sums, pairs[i], y);
    }
    return tooNear;
}

/// Both sides' points (p~ = P / W, relative to the output point) and Jacobians at each lane from
/// the sums; returns the lanes without a finite positive weight.
VOLMORPH_ALWAYS_INLINE inline v8i jetsFromSums(const Sums& sums, const Vec3d p[8],
                                               VelocityKernel::Jet out[8])
{
    const v8f* S = sums.v;
    const v8f W = S[Sums::W], one = splat8(1.0f);
    const v8i bad = !(W > 0.0f && W < std::numeric_limits<float>::infinity());
    const v8f invW = one / (bad ? one : W);
    for (int s = 0; s < 2; ++s) {
        const v8f* side = S + Sums::Side + Sums::PerSide * s;
        for (int a = 0; a < 3; ++a) {
            const v8f mean = side[Sums::P + a] * invW;
            for (int l = 0; l < 8; ++l) out[l].point[s][a] = p[l][a] + double(mean[l]);
            for (int b = 0; b < 3; ++b) {
                const v8f j = (side[Sums::M + 3 * a + b] - mean * S[Sums::Grad + b]) * invW;
                for (int l = 0; l < 8; ++l) out[l].jacobian[s](a, b) = double(j[l]);
            }
        }
    }
    return bad;
}

} // namespace

VOLMORPH_ALWAYS_INLINE inline int VelocityKernel::eightJetsBody(const Vec3d p[8], Jet out[8]) const
{
    const float near = float(std::max(mExactWithin, InverseWarp::kOnElement));
    v8f y[3];
    for (int a = 0; a < 3; ++a)
        for (int l = 0; l < 8; ++l) y[a][l] = float(p[l][a] - mReference[a]);
    Sums sums;
    const v8i bad = addPairs(mPairs, mWarp, y, near, sums) | jetsFromSums(sums, p, out);
    int lanes = 0;
    for (int l = 0; l < 8; ++l) lanes |= (bad[l] ? 1 : 0) << l;
    return lanes;
}

VOLMORPH_ALWAYS_INLINE inline int VelocityKernel::eightBody(const Vec3d p[8], Vec3d s[8],
                                                            Vec3d t[8], int& folds) const
{
    const float near = float(std::max(mExactWithin, InverseWarp::kOnElement));
    v8f y[3];
    for (int a = 0; a < 3; ++a)
        for (int l = 0; l < 8; ++l) y[a][l] = float(p[l][a] - mReference[a]);
    Sums sums;
    const v8i tooNear = addPairs(mPairs, mWarp, y, near, sums);
    Vec3d* v[2] = {s, t};
    v8i fold[2];
    const v8i bad = tooNear | quotientRule(sums, v, fold);
    const v8i folded = fold[0] | fold[1];
    int out = 0;
    folds = 0;
    for (int l = 0; l < 8; ++l) {
        out |= (bad[l] ? 1 : 0) << l;
        folds |= (folded[l] ? 1 : 0) << l;
    }
    return out;
}

#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 int VelocityKernel::eightJetsAvx2(const Vec3d p[8], Jet out[8]) const
{
    return eightJetsBody(p, out);
}
VOLMORPH_AVX512 int VelocityKernel::eightJetsAvx512(const Vec3d p[8], Jet out[8]) const
{
    return eightJetsBody(p, out);
}
VOLMORPH_AVX2 int VelocityKernel::eightAvx2(const Vec3d p[8], Vec3d s[8], Vec3d t[8],
                                            int& folds) const
{
    return eightBody(p, s, t, folds);
}
VOLMORPH_AVX512 int VelocityKernel::eightAvx512(const Vec3d p[8], Vec3d s[8], Vec3d t[8],
                                                int& folds) const
{
    return eightBody(p, s, t, folds);
}
#endif

int VelocityKernel::eightJetsBaseline(const Vec3d p[8], Jet out[8]) const
{
    return eightJetsBody(p, out);
}

int VelocityKernel::eightJets(const Vec3d p[8], Jet out[8]) const
{
    return (this->*pickBuild(mBuild, VOLMORPH_BUILDS(&VelocityKernel::eightJets)))(p, out);
}

void VelocityKernel::jets(const Vec3d* p, size_t n, Jet* out) const
{
    auto scalar = [&](const Vec3d& point, Jet& jet) {
        InverseWarp::Derivatives d[2];
        mWarp.map(point, jet.point[0], jet.point[1]);
        mWarp.derivatives(point, d[0], d[1]);
        for (int s = 0; s < 2; ++s) jet.jacobian[s] = d[s].jacobian;
    };
    for (size_t first = 0; first < n; first += 8) {
        const size_t count = std::min<size_t>(8, n - first);
        Vec3d points[8];
        Jet lanes[8];
        for (size_t l = 0; l < 8; ++l) points[l] = p[first + std::min(l, count - 1)];
        const int doubled = mPairs.empty() ? 0xff : eightJets(points, lanes);
        for (size_t l = 0; l < count; ++l) {
            if (doubled & (1 << l))
                scalar(points[l], out[first + l]);
            else
                out[first + l] = lanes[l];
        }
    }
}

int VelocityKernel::eightBaseline(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const
{
    return eightBody(p, s, t, folds);
}

int VelocityKernel::eight(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const
{
    return (this->*pickBuild(mBuild, VOLMORPH_BUILDS(&VelocityKernel::eight)))(p, s, t, folds);
}

void VelocityKernel::velocities(const Vec3d* p, size_t n, Vec3d* source, Vec3d* target,
                                bool* regular) const
{
    auto scalar = [&](const Vec3d& point, size_t i) {
        InverseWarp::Derivatives ds, dt;
        mWarp.derivatives(point, ds, dt);
        const bool s = InverseWarp::velocity(ds, source[i]);
        const bool t = InverseWarp::velocity(dt, target[i]);
        regular[i] = s && t;
    };
    if (mPairs.empty()) { // the identity
        for (size_t i = 0; i < n; ++i) scalar(p[i], i);
        return;
    }
    for (size_t first = 0; first < n; first += 8) {
        const size_t count = std::min<size_t>(8, n - first);
        Vec3d points[8], s[8], t[8];
        for (size_t l = 0; l < 8; ++l) points[l] = p[first + std::min(l, count - 1)];
        int folds = 0;
        const int doubled = eight(points, s, t, folds);
        for (size_t l = 0; l < count; ++l) {
            if (doubled & (1 << l)) {
                scalar(points[l], first + l);
            } else {
                source[first + l] = s[l];
                target[first + l] = t[l];
                regular[first + l] = !(folds & (1 << l));
            }
        }
    }
}

} // namespace volmorph::detail
