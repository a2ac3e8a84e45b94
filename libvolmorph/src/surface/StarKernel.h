// The kernel of a star-shaped mesh: the points from which all of its surface is seen, the
// intersection of the inner half-spaces of its triangles' planes (Kent, Carlson and Parent 1992
// project a mesh onto the sphere from such a point).
#pragma once

#include <volmorph/core/Math.h>

#include <cstdint>
#include <vector>

namespace volmorph::detail {

struct KernelPoint {
    Vec3d point;
    /// The least distance from `point` to a triangle's plane, positive on the inner side (world
    /// units); not positive: the mesh is not star-shaped (from any point, when `point` is the
    /// deepest).
    double margin = 0.0;
    uint32_t worstTriangle = 0; ///< the triangle whose plane is nearest (or seen from behind)
};

/// How deep `point` sits in the kernel of the closed, outward-facing mesh (`points`, `triangles`;
/// triangles without area are skipped).
KernelPoint kernelDepth(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                        const Vec3d& point);

/// The deepest point of the kernel (its Chebyshev centre): the point that maximises the least
/// distance to the triangles' planes. A linear programme in (x, y, z, depth) with a constraint per
/// triangle, solved by the primal active-set method from the vertex mean; O(triangles) per step,
/// a few dozen steps. When the kernel is empty, the point where it is nearest to being non-empty.
KernelPoint deepestKernelPoint(const std::vector<Vec3d>& points,
                               const std::vector<Vec3I>& triangles);

} // namespace volmorph::detail
