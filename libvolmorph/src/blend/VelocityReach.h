// The `vel` grid beyond the voxels blended. Eulerian motion blur (the renderer's, Cycles', Karma's)
// reads the velocity at a point and the density a shutter's motion upstream of it, so the velocity
// must also cover the voxels the density reaches within the shutter.
//
// The grid grows layer by layer (26 neighbours, the chessboard distance from the band) from the
// voxels blended. Each band voxel y reaches R(y) = |v(y)| seconds / voxel voxels; a voxel of layer
// k is kept while some band voxel reaches it along kept voxels,
//   r = max over its kept neighbours in layer k - 1 of their r, less 1 (layer 1: of R), r > 0,
// so where the surface moves slowly the grid stays close to it and where it moves fast it reaches
// far: the extension costs the surface's mean reach, not its fastest. A uniform speed keeps the
// layers up to ceil(R), as a uniform dilation would. At most ceil(reachSpeed seconds / voxel)
// layers (VelocityBlend::reachSpeed: a few spiking voxels do not set it), and kMaxReach.
//
// A new voxel holds the warp's own velocity there, (1 - tau) v_S + tau v_T (both sides empty),
// plus, in sdf mode, the band's normal correction carried outward: the mean of its kept
// neighbours' in layer k - 1, nearly constant along the normals as level-set methods extend a
// front's speed. Only two layers are alive at a time; the corrections of earlier layers wait in
// the velocity grid's own voxels until the warp's velocity is added to them, once per leaf.
// Units: corrections in index units per unit t, the grid in world units per second.
#pragma once

#include "blend/VelocityBlend.h"

#include <openvdb/openvdb.h>

#include <memory>

namespace volmorph::detail {

class VelocityReach {
public:
    /// seconds: the shutter's reach either way; voxelSize: world units.
    VelocityReach(const VelocityBlend& blend, double seconds, double voxelSize)
        : mBlend(blend), mSeconds(seconds), mVoxel(voxelSize)
    {
    }

    /// Grows `velocity` (world units per second, active at the voxels blended) over the reach.
    /// correction: the normal correction at those voxels (sdf mode), freed after the first layer;
    /// null: none. Returns the layers grown.
    int grow(openvdb::Vec3SGrid& velocity, std::unique_ptr<openvdb::Vec3STree> correction) const;

private:
    using VectorLeaf = openvdb::Vec3STree::LeafNodeType;
    struct Layer; // VelocityReach.cpp: one layer's voxels, reaches and where its values are
    /// Layer k + 1 from `last` (layer k; k = 0: the band): its voxels written into `velocity`
    /// (corrections, or zero), its reaches into the returned layer.
    Layer next(openvdb::Vec3STree& velocity, openvdb::MaskTree& visited, const Layer& last) const;
    /// The warp's velocity (world units per second) at every voxel grown (those of `velocity` not
    /// in `band`), plus their correction when `corrected`.
    void addWarp(openvdb::Vec3STree& velocity, const openvdb::MaskTree& band, bool corrected) const;

    const VelocityBlend& mBlend;
    double mSeconds, mVoxel;
};

} // namespace volmorph::detail
