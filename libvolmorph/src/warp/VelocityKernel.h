// The exact warp's velocities (InverseWarp::derivatives and ::velocity) at 8 points at a time in
// single precision, one point per lane, the pairs in turn: the velocity's hot loop
// (warp/VelocityLeaf.h evaluates it at its lattices and wherever they miss), written as the
// approximated warp writes its loops (warp/adaptive/) and built for the same instruction sets
// (AVX2, AVX2 with AVX-512VL, baseline; one body, the same IEEE operations per lane in each and the
// pairs in the same order, so a point's bits depend neither on the machine nor on the other points
// of its batch).
//
// The sums are the quotient rule's, merged where they are added anyway, with each side's point
// taken relative to the output point (p~_i = p_i - p', the pair's displacement: small numbers,
// so single precision keeps its digits where the quotient rule subtracts):
//   W = sum w_i, G = sum grad w_i, Q = sum dw_i/dt, P = sum w_i p~_i,
//   M = sum (w_i J_i + p~_i grad w_i^T), R = sum (w_i dp_i/dt + dw_i/dt p~_i)   (per side),
// so that J = (M - (P / W) G^T) / W and dW/dt = (R - (P / W) Q) / W (p' cancels), and
// v = -J^-1 dW/dt by the columns' cross products. Coordinates
// enter relative to a fixed reference point (the elements' mean origin), so that their size does
// not depend on where the scene sits. Single precision errs by about 1e-6 of the box across in
// each distance; a point whose d + offset is under `exactWithin` for some pair (where that error
// is a large part of it), or that has no finite positive weight, goes to InverseWarp::derivatives,
// in double.
#pragma once

#include "warp/AdaptiveWarp.h"

#include <openvdb/math/Mat3.h>

#include <volmorph/Warp.h>

#include <vector>

namespace volmorph::detail {

/// Both sides' warp velocities at points (output index space): what VelocityLeaf interpolates.
class PointVelocities {
public:
    virtual ~PointVelocities() = default;
    /// Both sides' velocities -J^-1 dW/dt at the n points p (the warp's units per unit t);
    /// `regular` false where J is singular (a fold: the velocity is 0).
    virtual void velocities(const Vec3d* p, size_t n, Vec3d* source, Vec3d* target,
                            bool* regular) const = 0;
};

class VelocityKernel final : public PointVelocities {
public:
    /// exactWithin: the d + offset (warp units) under which a point is evaluated in double
    /// precision. limit: the most capable build to use (for tests; the CPU may allow less).
    VelocityKernel(const InverseWarp& warp, double exactWithin,
                   KernelBuild limit = KernelBuild::Avx512);

    /// As InverseWarp::derivatives and InverseWarp::velocity give them.
    void velocities(const Vec3d* p, size_t n, Vec3d* source, Vec3d* target,
                    bool* regular) const override;

    /// Both sides' warped points and Jacobians at a point (the warp's units), as InverseWarp::map
    /// and ::derivatives give them: what TimedWarp blends between its levels.
    struct Jet {
        Vec3d point[2];
        openvdb::math::Mat3d jacobian[2];
    };
    /// The jets at the n points.
    void jets(const Vec3d* p, size_t n, Jet* out) const;

    /// One pair's quantities at t (WarpDerivatives.cpp's names), points relative to the kernel's
    /// reference point x0.
    struct Pair {
        enum Column {
            Origin = 0,      ///< + a: the element's origin c', less x0
            Axis = 3,        ///< + 3 k + a: component a of its frame's axis k
            Half = 12,       ///< + k: half its scale along axis k, 0 where the type does not extend
            HalfRate = 15,   ///< + k: d Half / dt
            Stretch = 18,    ///< + k: scale rate / scale along axis k
            OriginRate = 21, ///< + a: dc'/dt
            Omega = 24,      ///< + a: the frame's angular velocity
            LengthRate = 27, ///< the weight's own rate per unit weight (Beier-Neely's length)
            Affine = 28,     ///< + 12 side + 3 column + a: the affine map M, and (column 3)
                             ///< b~ = M x0 + b - x0: p~ = M y + b~ - y, y = p' - x0
            To = 52,         ///< + 9 side + 3 k + a: component a of the map's frame column k
            Count = 70
        };
        float v[Count];
    };

private:
    /// Velocities at 8 points; returns a bit per point that needs the double path, and `folds` a
    /// bit per point where J is singular.
    int eight(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const;
    int eightBaseline(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const;
    int eightAvx2(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const;
    int eightAvx512(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const;
    int eightBody(const Vec3d p[8], Vec3d s[8], Vec3d t[8], int& folds) const;
    /// Jets at 8 points; returns a bit per point that needs the double path.
    int eightJets(const Vec3d p[8], Jet out[8]) const;
    int eightJetsBaseline(const Vec3d p[8], Jet out[8]) const;
    int eightJetsAvx2(const Vec3d p[8], Jet out[8]) const;
    int eightJetsAvx512(const Vec3d p[8], Jet out[8]) const;
    int eightJetsBody(const Vec3d p[8], Jet out[8]) const;

    const InverseWarp& mWarp;
    Vec3d mReference;
    double mExactWithin;
    std::vector<Pair> mPairs;
    KernelBuild mBuild;
};

} // namespace volmorph::detail
