#include <volmorph/Warp.h>

#include <cmath>
#include <limits>

namespace volmorph {

namespace {

/// p_side = c_side + T (R'^T (p - c')) as p -> M p + b: M = T R'^T, b = c_side - M c'.
InverseWarp::Affine affineOf(const Feature& e, const Vec3d toSide[3], const Vec3d& sideOrigin)
{
    InverseWarp::Affine a;
    for (int c = 0; c < 3; ++c) {
        const Vec3d q(e.x[c], e.y[c], e.z[c]); // R'^T times the unit vector along axis c
        a.col[c] = toSide[0] * q.x() + toSide[1] * q.y() + toSide[2] * q.z();
    }
    a.offset = Vec3d(0.0);
    a.offset = sideOrigin - a.apply(e.origin);
    return a;
}

/// The linear part of an affine map, as a matrix (columns col).
openvdb::math::Mat3d linearPart(const InverseWarp::Affine& a)
{
    openvdb::math::Mat3d m;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i) m(i, c) = a.col[c][i];
    return m;
}

} // namespace

InverseWarp::InverseWarp(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec, double t,
                         double unit)
    : mWeighting(spec.weighting), mEpsilon(spec.epsilon * unit), mA(spec.a * unit), mB(spec.b),
      mP(spec.p)
{
    mPairs.reserve(pairs.size());
    for (const FeaturePairSpec& spec_ : pairs) {
        const Feature s = Feature::fromElement(spec_.source, spec_.type).scaled(unit);
        const Feature d = Feature::fromElement(spec_.target, spec_.type).scaled(unit);
        Pair p;
        p.element = interpolate(s, d, t);
        const Vec3d& e = p.element.scale;
        for (int k = 0; k < 3; ++k) {
            const Vec3d& sAxis = k == 0 ? s.x : k == 1 ? s.y : s.z;
            const Vec3d& tAxis = k == 0 ? d.x : k == 1 ? d.y : d.z;
            p.toSource[k] = sAxis * (s.scale[k] / e[k]);
            p.toTarget[k] = tAxis * (d.scale[k] / e[k]);
        }
        p.sourceOrigin = s.origin;
        p.targetOrigin = d.origin;
        p.lengthPow = std::pow(p.element.length(), spec.p);
        p.originRate = d.origin - s.origin;
        p.scaleRate = d.scale - s.scale;
        p.omega = angularVelocity(s, d);
        p.sourceJacobian = linearPart(affineOf(p.element, p.toSource, p.sourceOrigin));
        p.targetJacobian = linearPart(affineOf(p.element, p.toTarget, p.targetOrigin));
        mPairs.push_back(p);
    }
}

double InverseWarp::weight(const Pair& pair, double distance) const
{
    if (mWeighting == Weighting::InverseSquare) {
        const double r = distance + mEpsilon;
        return 1.0 / (r * r);
    }
    return std::pow(pair.lengthPow / (mA + distance), mB);
}

double InverseWarp::weightScale(size_t i) const
{
    return mWeighting == Weighting::InverseSquare ? 1.0 : std::pow(mPairs[i].lengthPow, mB);
}

void InverseWarp::map(const Vec3d& p, Vec3d& source, Vec3d& target) const
{
    if (mPairs.empty()) {
        source = target = p;
        return;
    }
    Vec3d sumS(0.0), sumT(0.0);
    double sumW = 0.0;
    Vec3d hitS(0.0), hitT(0.0);
    int hits = 0;
    for (const Pair& pair : mPairs) {
        const Vec3d q = pair.element.frameCoordinates(p);
        Vec3d ps, pt;
        images(pair, q, ps, pt);
        const double d = pair.element.distanceInFrame(q);
        if (mWeighting == Weighting::InverseSquare && d + mEpsilon < InverseWarp::kOnElement) {
            hitS += ps;
            hitT += pt;
            ++hits;
            continue;
        }
        const double w = weight(pair, d);
        sumS += w * ps;
        sumT += w * pt;
        sumW += w;
    }
    if (hits > 0) {
        source = hitS / double(hits);
        target = hitT / double(hits);
    } else {
        source = sumS / sumW;
        target = sumT / sumW;
    }
}

InverseWarp::Affine InverseWarp::sourceAffine(size_t i) const
{
    return affineOf(mPairs[i].element, mPairs[i].toSource, mPairs[i].sourceOrigin);
}

InverseWarp::Affine InverseWarp::targetAffine(size_t i) const
{
    return affineOf(mPairs[i].element, mPairs[i].toTarget, mPairs[i].targetOrigin);
}

InverseWarp::Motion InverseWarp::motion(size_t i) const
{
    const Pair& pair = mPairs[i];
    Motion m;
    m.originRate = pair.originRate;
    m.scaleRate = pair.scaleRate;
    m.omega = pair.omega;
    for (int k = 0; k < 3; ++k) {
        m.toSource[k] = pair.toSource[k];
        m.toTarget[k] = pair.toTarget[k];
    }
    if (mWeighting == Weighting::BeierNeely) { // as derivatives() takes it
        const Feature& e = pair.element;
        double lengthRate = 0.0, lengthSquared = 0.0;
        for (int k = 0; k < e.extendedAxes(); ++k) {
            lengthRate += e.scale[k] * pair.scaleRate[k];
            lengthSquared += e.scale[k] * e.scale[k];
        }
        if (lengthSquared > 0.0) m.lengthWeightRate = mB * mP * lengthRate / lengthSquared;
    }
    return m;
}

} // namespace volmorph
