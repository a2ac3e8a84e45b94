// The variational function's slice at one time: over a box of voxels, evaluated at every voxel
// (the reference the tests compare against), or near its zero set only, from a coarse lattice (a
// frame's).
#pragma once

#include "blend/variational/Interpolant.h"

#include <volmorph/core/Interrupter.h>

#include <openvdb/openvdb.h>

#include <functional>
#include <vector>

namespace volmorph::detail::variational {

/// The function at a point (x, y, z world units, w = t * time_scale) and, when `rate` is not
/// null, its derivative along w there.
using SliceFunction = std::function<double(const Point4&, double* rate)>;

/// A function split into parts, f = sum of smooth[k].f + detail: each smooth part varies slowly in
/// space at the scale of its `stride` (voxels, one of the screening's strides) and the levels finer
/// than that stride read it from a lattice of its own at that stride, tricubic between exact
/// values at its nodes; `detail` is taken exactly.
struct SplitFunction {
    struct Smooth {
        SliceFunction f;
        int stride = 8;
    };
    std::vector<Smooth> smooth;
    SliceFunction detail;
};

/// -f(x, y, z, w) at every voxel of `box` (index space of `transform`), so negative inside as
/// volmorph's signed distances are (not a distance: the function's own values), every voxel
/// active, background +|largest value|; a level set grid class so OpenVDB's tools read it.
openvdb::FloatGrid::Ptr sliceOverBox(const std::function<double(const Point4&)>& f, double w,
                                     const openvdb::math::Transform::Ptr& transform,
                                     const openvdb::CoordBBox& box);

struct NearZeroSlice {
    /// -f near its zero set, background +bandVoxels voxels (world units), level set class.
    openvdb::FloatGrid::Ptr values;
    /// -df/dw at the same voxels (dimensionless: world units of f per world unit of w), when
    /// asked for.
    openvdb::FloatGrid::Ptr rates;
    size_t evaluations = 0; ///< exact values taken
};

/// The slice near its zero set only, from exact values on a lattice every `stride` voxels: a
/// lattice cell is kept when its corners' values change sign, or when the smallest of them is
/// within `bandVoxels` of zero and an allowance for f's curvature (stride^2 / 8 voxels, at most a
/// stride) at the steepest slope between its corners (never under a distance's; f grows about as
/// the distance near the shapes, its constraints' values being distances); kept cells get every
/// voxel, tricubic (Catmull-Rom) between the lattice's values: at a stride of 2, within 0.013
/// voxel of the exact values on a sphere becoming two (4: 0.15; trilinear at 2: 0.15, at 4: 0.95).
/// The lattice is screened coarsest first: 16 strides apart over the box, then halving, each level
/// evaluating the corners of the cells inside those its parent kept, and the finest level the
/// nodes of its kept cells' tricubic stencils too. With `withRates`, df/dw is taken at the same
/// lattice points and interpolated the same way. Throws Interrupted when `interrupter` asks to
/// stop.
///
/// With a split function, each smooth part's lattice holds exact values at the nodes around the
/// cells its level kept and their neighbours (where every finer level's nodes lie).
NearZeroSlice sliceNearZero(const SplitFunction& f, double w,
                            const openvdb::math::Transform::Ptr& transform,
                            const openvdb::CoordBBox& box, int stride, double bandVoxels,
                            bool withRates = false, Interrupter* interrupter = nullptr);

/// sliceNearZero of f alone, every value exact at the lattice's nodes.
NearZeroSlice sliceNearZero(const SliceFunction& f, double w,
                            const openvdb::math::Transform::Ptr& transform,
                            const openvdb::CoordBBox& box, int stride, double bandVoxels,
                            bool withRates = false, Interrupter* interrupter = nullptr);

} // namespace volmorph::detail::variational
