// The overlay of two triangulations of the sphere (Kent, Carlson and Parent 1992, "map merging"):
// every vertex of both, every point where an edge of one crosses an edge of the other, and the
// faces split into the smallest regions: each region is the intersection of a triangle of each
// side, a convex spherical polygon of at most six vertices, then cut into triangles.
//
// Every decision is an orientation predicate on the inputs' grid directions (SpherePredicates.h),
// exact and with ties broken by Simulation of Simplicity, so the merged network is a valid
// triangulation of the sphere whatever the inputs' coincidences. Crossings are the only new
// points; their directions are computed in double precision and cut into triangles with the exact
// predicate on their grid directions.
//
// Cost: O(V_A + V_B + crossings) predicates after one point location; the regions are found by a
// walk from region to neighbouring region.
#pragma once

#include "SpherePredicates.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace volmorph::detail {

/// A closed triangulation of the sphere: each triangle counter-clockwise seen from outside and
/// smaller than a hemisphere, each edge shared by exactly two triangles.
struct SphereTriangulation {
    std::vector<GridDirection> directions;
    std::vector<Vec3I> triangles;
};

struct OverlayVertex {
    enum class Kind : uint8_t { Source, Target, Crossing };
    Kind kind = Kind::Source;
    /// A triangle of each side that holds the vertex (for a side's own vertex, one of its corners).
    uint32_t sourceTriangle = 0, targetTriangle = 0;
    /// Source: source[0] is the vertex. Target: target[0]. Crossing: the source edge
    /// (source[0], source[1]) and the target edge (target[0], target[1]).
    uint32_t source[2] = {0, 0}, target[2] = {0, 0};
};

struct Overlay {
    std::vector<OverlayVertex> vertices; ///< the sources', then the targets', then crossings
    std::vector<Vec3d> directions;       ///< per vertex, unit
    std::vector<GridDirection> grid;     ///< per vertex, as the predicates see it
    std::vector<Vec3I> triangles;        ///< counter-clockwise seen from outside
    /// per triangle: the source's and the target's triangle whose intersection it is part of
    std::vector<std::pair<uint32_t, uint32_t>> regions;
    size_t crossings = 0;
    size_t unclipped = 0; ///< regions cut by a fan because no exact ear was found (should be 0)
};

/// The overlay of `source` and `target`. Throws std::runtime_error when an input is not a closed
/// triangulation of the sphere (an edge without its twin) or the walk does not close a region
/// (which the exact predicates rule out for valid inputs).
Overlay overlay(const SphereTriangulation& source, const SphereTriangulation& target);

/// The triangles of `grid`'s triangulation that are not strictly counter-clockwise (exact).
size_t invertedTriangles(const std::vector<GridDirection>& grid,
                         const std::vector<Vec3I>& triangles);

} // namespace volmorph::detail
