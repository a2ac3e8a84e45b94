// The inverse warp of feature-based volume morphing.
//
// For an output point p' and pair i with interpolated element e'_i: u = R'^T (p' - c') / s', and
// the pair maps p' to p_i = c + R (u * s) on each side (an affine map). The warped point is sum w_i
// p_i / sum w_i with w_i = (d(p', e'_i) + epsilon)^-2, or Beier-Neely's (length^p / (a + d))^b.
// With no pairs the warp is the identity; at t = 0 the source side is the identity, at t = 1 the
// target side.
#pragma once

#include <volmorph/Feature.h>
#include <volmorph/WarpSettings.h>

#include <openvdb/math/Mat3.h>

#include <vector>

namespace volmorph {

class InverseWarp {
public:
    /// Pairs at time t. `unit` scales lengths: 1 for world units, 1 / voxel size for index space
    /// (the normalized weights do not depend on it; epsilon and a are scaled with it).
    InverseWarp(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec, double t,
                double unit = 1.0);

    /// Below this, d + offset counts as zero: the point lies on an element and that pair alone
    /// decides (with several such pairs, their mean). Keeps every weight finite when epsilon = 0.
    static constexpr double kOnElement = 1e-12;

    /// The exact warp: p' -> (source point, target point).
    void map(const Vec3d& p, Vec3d& source, Vec3d& target) const;

    /// One side's warp W (output point -> that side's point) differentiated at an output point:
    /// J = dW/dp' and dW/dt, t the morph time (lengths in the warp's units).
    struct Derivatives {
        openvdb::math::Mat3d jacobian = openvdb::math::Mat3d::identity();
        Vec3d rate{0.0};
    };
    /// The exact warp's derivatives at p', analytic (through each pair's weight as well as its
    /// map; where p' lies on elements, the mean of their maps').
    void derivatives(const Vec3d& p, Derivatives& source, Derivatives& target) const;
    /// The velocity of what one side shows at p': -J^-1 dW/dt, in the warp's units per unit of t.
    /// False where J is singular (the warp folds there): then v is 0.
    static bool velocity(const Derivatives& d, Vec3d& v);

    /// Every weight follows w_i(d) = scale_i (offset + d)^-exponent: inverse square is scale 1,
    /// offset epsilon, exponent 2; Beier-Neely is scale length_i^(p b), offset a, exponent b.
    /// Lengths (offset, d) are in the units the warp was built with.
    double weightOffset() const { return mWeighting == Weighting::InverseSquare ? mEpsilon : mA; }
    double weightExponent() const { return mWeighting == Weighting::InverseSquare ? 2.0 : mB; }
    double weightScale(size_t i) const;
    Weighting weighting() const { return mWeighting; }
    /// Pair i's weight at distance d from its interpolated element.
    double weightAt(size_t i, double d) const { return weight(mPairs[i], d); }

    size_t pairCount() const { return mPairs.size(); }
    const Feature& interpolated(size_t i) const { return mPairs[i].element; }

    /// The affine map of pair i on each side, as p -> M p + b, for bounding the output domain.
    struct Affine {
        Vec3d col[3]; ///< columns of M
        Vec3d offset; ///< b
        Vec3d apply(const Vec3d& p) const
        {
            return col[0] * p.x() + col[1] * p.y() + col[2] * p.z() + offset;
        }
    };
    Affine sourceAffine(size_t i) const;
    Affine targetAffine(size_t i) const;

    /// How pair i's interpolated element moves per unit t, for the velocity's vector kernel
    /// (derivatives() and velocity() written for 8 points at a time): its origin and scales
    /// change linearly and its frame turns at omega; the maps from frame coordinates q take each
    /// side to origin + sum_k to[k] q_k; the weight's own rate (Beier-Neely's length term) is
    /// lengthWeightRate times the weight.
    struct Motion {
        Vec3d originRate, scaleRate, omega;
        Vec3d toSource[3], toTarget[3];
        double lengthWeightRate = 0.0;
    };
    Motion motion(size_t i) const;

private:
    struct Pair {
        Feature element;   ///< interpolated at t
        Vec3d toSource[3]; ///< R_S diag(s_S / s') as columns: p_S = c_S + toSource * q
        Vec3d toTarget[3];
        Vec3d sourceOrigin, targetOrigin;
        double lengthPow = 1; ///< length^p, Beier-Neely only
        /// How the element moves per unit t: origin and scales (linear) and its frame's turn.
        Vec3d originRate, scaleRate, omega;
        /// d p_side / d p' at t: the linear parts of the affine maps (sourceAffine, targetAffine).
        openvdb::math::Mat3d sourceJacobian, targetJacobian;
    };
    double weight(const Pair& pair, double distance) const;
    /// Pair's affine images on both sides of the point with frame coordinates q.
    static void images(const Pair& pair, const Vec3d& q, Vec3d& source, Vec3d& target)
    {
        source = pair.sourceOrigin + pair.toSource[0] * q.x() + pair.toSource[1] * q.y() +
                 pair.toSource[2] * q.z();
        target = pair.targetOrigin + pair.toTarget[0] * q.x() + pair.toTarget[1] * q.y() +
                 pair.toTarget[2] * q.z();
    }

    std::vector<Pair> mPairs;
    Weighting mWeighting;
    double mEpsilon, mA, mB, mP;
};

} // namespace volmorph
