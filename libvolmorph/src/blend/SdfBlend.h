// sdf mode: blends the two sides' signed distances, (1 - tau) d_S + tau d_T at the warped points
// (tau: the sdf schedule at t), so the in-between's surface is the blend's zero set; colour is
// blended on its band (ColorBlend.h, each side weighted by the fog of its distance).
//
// Once per morph both distance fields are extended beyond their bands (ExtendedDistance.h) over
// the box of source and target together, plus a margin. A frame evaluates the blend only where its
// band can be (SdfFrame.h, BlockClasses.h): the blend's gradient is at most the warp's stretch G,
// so a leaf or a part of one whose centre value is farther from zero than G times its reach plus
// the band is inside or outside as a whole. In the rest, dust is removed (Islands.h,
// blend.min_island), the band is rebuilt to first order (Redistance.h), and the fog is derived
// from it. With `prune` false every voxel of the box is evaluated: the tests' reference.
//
// With no feature pairs the warp is the identity at every t: both extended distances at a voxel
// are then the same in every frame, and are kept per leaf from the first frame that needs them,
// as are those at the leaves' centres (IdentityDistances.h; the frames are the same bit for bit,
// only the blend's weight changes with t). The extended fields then need only the objects' box
// plus 8 voxels.
#pragma once

#include "blend/BlendMethod.h"

namespace volmorph::detail {

std::unique_ptr<const BlendMethod> makeSdfBlend(const BlendSetup& setup);

} // namespace volmorph::detail
