// The part of Kent's merge that every correspondence through the sphere shares (star: each mesh
// seen from its kernel; sphere: each mesh's spherical parameterization): both sides' triangles on
// the unit sphere, overlaid (SphereOverlay.h), and every merged vertex placed back on both
// surfaces through its barycentric weights in the triangle of each side it falls in, with the
// colours the same way.
#pragma once

#include "MergeSide.h"
#include "SphereOverlay.h"

#include <functional>

namespace volmorph::detail {

struct SphereSide {
    const MergeSide* side = nullptr;
    std::vector<Vec3d> directions; ///< per vertex, a unit vector (the target's after any warp)
    /// Per vertex, how far along its direction its point lies from where the directions are seen
    /// from (star: |p - kernel|, so that a direction maps back along the ray); all 1 for a map
    /// onto the sphere (the point in the chord triangle maps back by its weights).
    std::vector<double> depth;
};

/// When merged vertex `v` is one of side `s`'s own vertices (isSource: the source's), its point
/// and colour, and true; else false.
bool placeOwnVertex(const MergeSide& s, const OverlayVertex& v, bool isSource, Vec3d& at,
                    Vec3f* color);

/// Throws the caller's error for a triangle of one side that is not counter-clockwise on the
/// sphere (isSource, the triangle's index).
using TurnedOver = std::function<void(bool isSource, uint32_t triangle)>;

/// The merged mesh of `a` (source) and `b` (target), its `used` set to `used`. A vertex of one
/// side exactly on an edge of the other leaves regions without area: the target's sphere is then
/// turned (MergeSide.h's mergeTurn) and merged again. Throws UserError at `where` when every turn
/// leaves a region without area.
Corresponded mergeSides(const SphereSide& a, const SphereSide& b, Correspondence used,
                        const TurnedOver& turnedOver, const SourceLocation& where);

} // namespace volmorph::detail
