// Exact orientation on the sphere, for the overlay of two spherical triangulations (Kent's merge).
//
// A direction is stored on an integer grid: its unit vector times 2^40, rounded. The orientation of
// three directions (the sign of det(p, q, r), positive when r lies to the left of the great circle
// from p to q) is then computed exactly: each product of three coordinates is below 2^120 and the
// sum of six below 2^123, which a 128-bit integer holds.
//
// Ties (det = 0: a vertex of one mesh on an edge of the other, two vertices in one direction) are
// broken by Simulation of Simplicity (Edelsbrunner and Muecke 1990): every coordinate is moved by
// its own infinitesimal, smaller for later points, so every predicate has a sign and all the signs
// are those of one configuration in general position.
#pragma once

#include <volmorph/core/Math.h>

#include <cstdint>

namespace volmorph::detail {

struct GridDirection {
    int64_t x = 0, y = 0, z = 0;
    bool operator==(const GridDirection& o) const { return x == o.x && y == o.y && z == o.z; }
};

inline constexpr double kGridScale = 1099511627776.0; // 2^40

/// `unit` (a unit vector) on the grid.
GridDirection toGrid(const Vec3d& unit);
/// The grid direction as a unit vector.
Vec3d fromGrid(const GridDirection& g);

/// The sign of det(p, q, r): +1, 0 or -1, exactly.
int orientation(const GridDirection& p, const GridDirection& q, const GridDirection& r);

/// The sign of det(p, q, r) after the symbolic perturbation; never 0 for three distinct indices.
/// ip, iq, ir name the points (the perturbation of a point depends on its index only).
int orientationSoS(const GridDirection& p, uint32_t ip, const GridDirection& q, uint32_t iq,
                   const GridDirection& r, uint32_t ir);

} // namespace volmorph::detail
