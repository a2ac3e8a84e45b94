// The exact warp's derivatives, for velocity: W(p', t) = sum w_i p_i / sum w_i on each side, with
// p_i = c_i + T_i(t) q_i(p', t) and q_i = R'_i(t)^T (p' - c'_i(t)) the point in pair i's
// interpolated frame, and w_i a function of the distance d_i(q_i, s'_i(t)) to that element (and,
// Beier-Neely, of its length). By the quotient rule
//   dW/dp' = (sum w_i dp_i/dp' + sum (p_i - W) grad w_i^T) / sum w_i,
//   dW/dt  = (sum w_i dp_i/dt  + sum (p_i - W) dw_i/dt)     / sum w_i,
// with the element moving linearly (origin, scales) and turning at a constant angular velocity
// omega_i (slerp), so that dq/dt = R'^T ((p' - c') x omega - dc'/dt).
#include <volmorph/Warp.h>

#include <cmath>

namespace volmorph {

using Mat3d = openvdb::math::Mat3d;

namespace {

/// a b^T.
Mat3d outer(const Vec3d& a, const Vec3d& b)
{
    Mat3d m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m(i, j) = a[i] * b[j];
    return m;
}

/// Pair i's map on one side at frame coordinates q, and its derivatives: the map is
/// origin + sum_k to[k] q_k, and to[k] = axis_k s_k / s'_k(t) shrinks as the element's scale grows;
/// its Jacobian (the affine map's linear part) is the pair's, made once per warp.
struct Image {
    Vec3d p, rate;
    const Mat3d& jacobian;
    Image(const Vec3d to[3], const Vec3d& origin, const Mat3d& linear, const Feature& e,
          const Vec3d& q, const Vec3d& qRate, const Vec3d& scaleRate)
        : p(origin), rate(0.0), jacobian(linear)
    {
        for (int k = 0; k < 3; ++k) {
            p += to[k] * q[k];
            rate += to[k] * (qRate[k] - q[k] * scaleRate[k] / e.scale[k]);
        }
    }
};

/// One side's running sums over the pairs (the quotient rule's terms), and over the elements the
/// point lies on.
struct Sums {
    Vec3d wp{0.0}, wRate{0.0}, pwRate{0.0};
    Mat3d wJacobian = Mat3d::zero(), pGradW = Mat3d::zero();
    Vec3d hitRate{0.0};
    Mat3d hitJacobian = Mat3d::zero();

    void add(const Image& image, double w, const Vec3d& gradW, double wRate_)
    {
        wp += w * image.p;
        wJacobian += image.jacobian * w;
        pGradW += outer(image.p, gradW);
        wRate += w * image.rate;
        pwRate += wRate_ * image.p;
    }
    void hit(const Image& image)
    {
        hitJacobian += image.jacobian;
        hitRate += image.rate;
    }
    InverseWarp::Derivatives result(int hits, double sumW, const Vec3d& sumGradW,
                                    double sumWRate) const
    {
        InverseWarp::Derivatives d;
        if (hits > 0) {
            d.jacobian = hitJacobian * (1.0 / hits);
            d.rate = hitRate / double(hits);
            return d;
        }
        const Vec3d w = wp / sumW;
        d.jacobian = (wJacobian + pGradW - outer(w, sumGradW)) * (1.0 / sumW);
        d.rate = (wRate + pwRate - w * sumWRate) / sumW;
        return d;
    }
};

} // namespace

void InverseWarp::derivatives(const Vec3d& p, Derivatives& source, Derivatives& target) const
{
    source = target = Derivatives{};
    if (mPairs.empty()) return; // the identity
    Sums s, t;
    double sumW = 0.0, sumWRate = 0.0;
    Vec3d sumGradW(0.0);
    int hits = 0;
    for (const Pair& pair : mPairs) {
        const Feature& e = pair.element;
        const Vec3d q = e.frameCoordinates(p);
        const Vec3d u = (p - e.origin).cross(pair.omega) - pair.originRate;
        const Vec3d qRate(e.x.dot(u), e.y.dot(u), e.z.dot(u));
        const Image is(pair.toSource, pair.sourceOrigin, pair.sourceJacobian, e, q, qRate,
                       pair.scaleRate);
        const Image it(pair.toTarget, pair.targetOrigin, pair.targetJacobian, e, q, qRate,
                       pair.scaleRate);
        const double d = e.distanceInFrame(q);
        if (mWeighting == Weighting::InverseSquare && d + mEpsilon < kOnElement) {
            s.hit(is);
            t.hit(it);
            ++hits;
            continue;
        }
        // The distance's gradient (0 inside a box) and rate; only the extended axes' scales move
        // the nearest point, away from q by half their change.
        const Vec3d off = e.offsetFromElement(q);
        const double offLength = off.length();
        const Vec3d g = offLength > 0.0 ? off / offLength : Vec3d(0.0);
        double dRate = g.dot(qRate);
        double lengthRate = 0.0, lengthSquared = 0.0; // d(length)/dt / length, Beier-Neely
        for (int k = 0; k < e.extendedAxes(); ++k) {
            dRate -= 0.5 * std::abs(g[k]) * pair.scaleRate[k];
            lengthRate += e.scale[k] * pair.scaleRate[k];
            lengthSquared += e.scale[k] * e.scale[k];
        }
        const double w = weight(pair, d);
        double dwdd, wRate = 0.0;
        if (mWeighting == Weighting::InverseSquare) {
            dwdd = -2.0 * w / (d + mEpsilon);
        } else {
            dwdd = -mB * w / (mA + d);
            if (lengthSquared > 0.0) wRate = mB * mP * w * lengthRate / lengthSquared;
        }
        const Vec3d gradW = dwdd * (e.x * g.x() + e.y * g.y() + e.z * g.z());
        wRate += dwdd * dRate;
        s.add(is, w, gradW, wRate);
        t.add(it, w, gradW, wRate);
        sumW += w;
        sumGradW += gradW;
        sumWRate += wRate;
    }
    source = s.result(hits, sumW, sumGradW, sumWRate);
    target = t.result(hits, sumW, sumGradW, sumWRate);
}

bool InverseWarp::velocity(const Derivatives& d, Vec3d& v)
{
    // J^-1 by its columns' cross products: the rows of adj(J) are c1 x c2, c2 x c0, c0 x c1.
    const Vec3d c0 = d.jacobian.col(0), c1 = d.jacobian.col(1), c2 = d.jacobian.col(2);
    const Vec3d a0 = c1.cross(c2), a1 = c2.cross(c0), a2 = c0.cross(c1);
    const double det = c0.dot(a0);
    if (!(std::abs(det) > 1e-12)) {
        v = Vec3d(0.0);
        return false;
    }
    v = Vec3d(a0.dot(d.rate), a1.dot(d.rate), a2.dot(d.rate)) * (-1.0 / det);
    return true;
}

} // namespace volmorph
