// sdf mode's velocity, the `vel` grid. The in-between's field
//   phi = (1 - tau) d_S(W_S) + tau d_T(W_T)
// moves as its level sets do, with the warp and with the changing blend. The warp's velocity v_w
// (each side's -J^-1 dW/dt, warp/VelocityLeaf.h, mixed by each side's fog as colour is) keeps its
// tangential part; its normal part is replaced so that phi_t + v . grad phi = 0:
//   v = v_w + ((-phi_t - v_w . grad phi) / |grad phi|^2) grad phi,
//   phi_t = tau_t (d_T(W_T) - d_S(W_S)) - (1 - tau) g_S . v_S - tau g_T . v_T,
//   grad phi = (1 - tau) g_S + tau g_T + (d_T(W_T) - d_S(W_S)) grad tau,
// g the gradient, at the output voxel, of the side's warped distance d(W) (g . v = grad d . J v =
// -grad d . dW/dt). The warped distances are the frame's own, recorded where its leaves were
// blended (SdfFrame::Distances); their gradients are central differences over the output's voxels
// (one-sided, second order, at the edge of what was recorded). Where |grad phi| is below a quarter
// of a distance's (the sides' gradients cancel, as where a surface splits in two), the normal is
// undefined and the voxel keeps v_w. Under a timing tau is each voxel's (BlendTime.h): tau_t is
// the schedule's slope times d tau / d t there, and grad tau the delay's chain rule; without one
// tau_t is the schedule's slope at t and grad tau is 0.
//
// Beyond the voxels blended, out to the shutter's reach (VelocityReach.h), the velocity is the
// warp's, (1 - tau) v_S + tau v_T, plus the normal correction v - v_w extended outward layer by
// layer, each new voxel taking the mean of its 26 neighbours' from the layer before: nearly
// constant along the normals, as level-set methods extend a front's speed.
// Units: index units per unit t inside, world units per second in the grid.
#pragma once

#include "blend/BlendTime.h"
#include "blend/VelocityBlend.h"

#include <openvdb/openvdb.h>

namespace volmorph::detail {

class SdfVelocity {
public:
    /// worldPerSecond: world units per second of one index unit per unit t; time: the distance
    /// schedule's tau at each voxel (it must outlive this); rampWorld: the fog's ramp, voxelSize:
    /// the output's voxel (world units).
    SdfVelocity(const FrameWarp& warp, double worldPerSecond, const BlendTime& time,
                float rampWorld, float voxelSize)
        : mBlend(warp, worldPerSecond, time), mScale(float(worldPerSecond)), mTime(time),
          mRamp(rampWorld), mShell(rampWorld + 2.0f * voxelSize)
    {
    }

    /// The velocity grid (world units per second) at the voxels where both distances were
    /// recorded (world units, the output's index space) and the blend is within the fog's ramp and
    /// two voxels of the surface, and over the reach of `seconds` beyond.
    openvdb::Vec3SGrid::Ptr make(const openvdb::FloatTree& source, const openvdb::FloatTree& target,
                                 double seconds, double voxelSize) const;

    uint64_t interpolatedCubes() const { return mBlend.interpolatedCubes(); }
    uint64_t exactCubes() const { return mBlend.exactCubes(); }

private:
    using VectorLeaf = openvdb::Vec3STree::LeafNodeType;
    /// Where the formula holds: the voxels recorded whose blend is within mShell of zero.
    openvdb::MaskTree shell(const openvdb::FloatTree& source,
                            const openvdb::FloatTree& target) const;
    /// One leaf of the velocity (world units per second) and, unless null, of the correction
    /// v - v_w (index units per unit t), at the velocity leaf's active voxels.
    void leaf(const openvdb::FloatTree& source, const openvdb::FloatTree& target,
              VectorLeaf& velocity, VectorLeaf* correction) const;

    VelocityBlend mBlend;
    float mScale;
    const BlendTime& mTime;
    float mRamp;
    float mShell; ///< world units: where |phi| is below it, the formula; beyond, the extension
};

} // namespace volmorph::detail
