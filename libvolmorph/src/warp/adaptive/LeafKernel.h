// The approximated warp's leaf kernel: fills a leaf's 512 points by rows of 8 voxels along z, the
// far pairs' sums interpolated from the leaf's corners, the near pairs evaluated at every voxel.
#pragma once

#include "warp/AdaptiveWarp.h"

#include <volmorph/Feature.h>
#include <volmorph/Warp.h>

#include <vector>

namespace volmorph::detail {

/// An affine function of the voxel (i, j, k), a + b i + c j + d k, as the rows walk it: a + b i at
/// each slice i in double (then single precision), c and d in single precision.
struct RowAffine {
    float start[8]; ///< at the first voxel of each slice (j = k = 0)
    float dy;       ///< step along y: from one row to the next
    float dz;       ///< step along z: from one voxel of a row to the next
    void set(double a, double b, double c, double d)
    {
        for (int i = 0; i < 8; ++i) start[i] = float(a + b * i);
        dy = float(c);
        dz = float(d);
    }
};

/// One near pair's share of a leaf: its element, weight scale and residuals R = A - B at the
/// leaf's origin, whose steps along the axes are the columns of M_A - M_B.
struct NearTerm {
    const Feature* element;
    double scale;
    double half[3]; ///< half the scales, 0 on the axes the type does not extend along
    Vec3d rs, drs[3], rt, drt[3];
};

/// A near pair ready for the rows: its frame coordinates and residuals over the leaf.
struct NearRows {
    RowAffine f[9]; ///< frame coordinates q, source residual, target residual
    float half[3];
    float scale;
};

/// Everything that fills one leaf's points.
struct LeafJob {
    Vec3d origin;
    /// At the leaf's corners (bit 0: +x, bit 1: +y, bit 2: +z), channels as the kernel's sums:
    /// the exact W, S - W B and T - W B, less the near pairs in fillLeafBody: the far sums.
    double far[7][8];
    std::vector<NearTerm> near; ///< grouped by type: Point, Segment, Rectangle, Box
    size_t typeEnd[4];          ///< where each type's near pairs end in `near`
    std::vector<NearRows> rows; ///< scratch, one per near pair
    InverseWarp::Affine bS, bT; ///< the dominant pair's affine maps
    double offset, exponent;
    bool inverseSquare;
};

/// Fills `leaf` (its origin set) from `job` with the kernel build `build`.
void fillLeaf(LeafJob& job, WarpLeaf& leaf, KernelBuild build);

/// The box of a leaf's warped points on each side (0 source, 1 target).
void leafRange(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2], KernelBuild build);

} // namespace volmorph::detail
