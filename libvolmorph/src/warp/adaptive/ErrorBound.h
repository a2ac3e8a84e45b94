// The approximated warp's a-priori error bound over a cube of voxels (AdaptiveWarp.h, step 3):
// each pair's bounds of its weight's slope and curvature, its share of the error when it is far,
// and which pairs must be near for the bound to hold the tolerance.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace volmorph::detail {

/// Trilinear interpolation bounds the error by h^2/8 (|u_xx| + |u_yy| + |u_zz|) (see
/// AdaptiveWarp.h). The bound is a worst case over the leaf; 1 keeps it a bound.
inline constexpr double kBoundScale = 1.0;

/// Below this offset + distance (index units) the weights are too steep to trust the arithmetic
/// of the sums: the leaf is evaluated exactly (only with a zero or tiny epsilon).
inline constexpr double kTinyRadius = 1e-6;

/// Everything the error bound needs of each pair over a cube, one column per quantity (single
/// precision: its rounding, some 1e-7 of each term, is far inside the bound's slack). Stored in
/// groups of 8 pairs, all columns of a group together (one base address for a loop's loads and
/// stores: the columns' own pointers no longer compete for registers).
struct PairBounds {
    enum Column {
        WeightMax,   ///< w_i at its smallest distance over the cube
        SlopeBound,  ///< sup |grad w_i| over the cube (0 where constant)
        CurveBound,  ///< sum over axes a of sup |d_aa w_i| (infinite at a kink; 0 where constant)
        Constant,    ///< 1 where a box contains the whole cube: w_i is constant there
        ResidualMax, ///< sup |R_i| = |A_i - B| over the cube, the larger side
        ResidualS0,  ///< + a: R_i at the cube's centre, source side, axis a
        ResidualS1,
        ResidualS2,
        ResidualT0, ///< + a: the same, target side
        ResidualT1,
        ResidualT2,
        Share,      ///< the pair's share of the bound's numerator when far (infinite: a kink)
        CurveShare, ///< h^2/8 CurveBound: what interpolating w_i may take off the total weight
        Count
    };
    struct Group {
        float v[Count][8];
    };
    std::vector<Group> groups;
    void resize(size_t padded) { groups.resize(padded / 8); }
    float get(Column c, size_t i) const { return groups[i / 8].v[c][i % 8]; }
};

/// The bound from the far pairs' summed shares `shares` and curve shares `curve`: over the
/// smallest interpolated total weight W_E + I[W_F], at least the smallest total weight
/// `wMinSum` less what interpolating W_F may take, and at least `floor` (with every pair far,
/// I[W] is a convex combination of the corners' W: their smallest). Infinite when unbounded.
inline double errorBound(double wMinSum, double shares, double curve, double floor)
{
    const double denominator = std::max(wMinSum - curve, floor);
    return std::isfinite(shares) && denominator > 0.0 ? shares / denominator
                                                      : std::numeric_limits<double>::infinity();
}

} // namespace volmorph::detail
