// Spherical parameterization of a closed genus-0 mesh by its progressive mesh (Praun and Hoppe
// 2003, "Spherical parametrization and remeshing"): the mesh is simplified by half-edge collapses
// (OpenMesh's quadric decimater) to a tetrahedron, which is placed on the unit sphere as a regular
// one; the collapses are then undone one vertex split at a time, each new vertex placed inside
// the spherical kernel of its ring (next to the vertex it splits from, on the side of its
// triangles) and both relaxed to lower the map's stretch (SphereStretch.h), with the whole map
// relaxed each time the mesh has grown by a quarter. No step accepts a triangle turned over, so
// the map stays one-to-one all the way up.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/core/Math.h>

#include <vector>

namespace volmorph::detail {

struct SphereMap {
    std::vector<Vec3d> directions;  ///< per vertex, a unit vector
    double stretchEfficiency = 0.0; ///< Praun and Hoppe's L2 measure, in (0, 1]
    size_t collapses = 0;           ///< the progressive mesh's vertex splits
};

/// The map of the closed, genus-0, consistently oriented (outward) manifold mesh (`points`, world
/// units; `triangles`, every vertex used) onto the unit sphere: every triangle counter-clockwise
/// seen from outside by the exact predicate on SpherePredicates' grid, their spherical areas
/// adding up to 4 pi. Throws std::runtime_error if the mesh cannot be simplified to a tetrahedron
/// (it is not such a mesh), Interrupted when `interrupter` asks to stop.
SphereMap sphericalMap(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                       Interrupter* interrupter = nullptr);

} // namespace volmorph::detail
