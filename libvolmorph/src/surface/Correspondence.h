// Correspondence: two meshes become one connectivity with a place on each surface: the identity
// (the same vertices and triangles), Kent's star-shaped merge (StarMerge.h), the spherical map's
// merge (SphereMerge.h) or the disk map's (DiskMerge.h).
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/Mesh.h>
#include <volmorph/SurfaceSettings.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace volmorph::detail {

/// The two sides on one connectivity: vertex i of `source` and of `target` is the same point of
/// the correspondence, on each input's surface (world units, double precision: a merged vertex
/// lies inside an input triangle, not at a float).
struct Corresponded {
    std::vector<Vec3d> source, target;
    std::vector<Vec3I> triangles;
    /// Per vertex, linear RGB; both empty when neither input has colours (a side without them is
    /// grey).
    std::vector<Vec3f> sourceColors, targetColors;
    /// Per triangle corner (3 per triangle), each side's texture coordinates there; both empty
    /// when neither input has them (a side without them has (0, 0)).
    std::vector<Vec2d> sourceUVs, targetUVs;
    Correspondence used = Correspondence::Identity;
    size_t crossings = 0; ///< merged: the points where an edge of one crossed an edge of the other
    /// star: the points each side was projected from (world units)
    std::optional<std::pair<Vec3d, Vec3d>> kernels;
    /// sphere: each map's L2 stretch efficiency (Praun and Hoppe; 1 = no stretch)
    std::optional<std::pair<double, double>> stretch;
};

/// Why the identity does not apply to these meshes ("" when it does).
std::string identityMismatch(const Mesh& source, const Mesh& target);

/// Why Kent's merge and the spherical map do not apply (not a closed genus-0 surface of one
/// piece), "" when they may (whether the mesh is star-shaped is found by the merge).
std::string starMismatch(const Mesh& mesh);

/// Puts the meshes into correspondence as `spec` says. Throws UserError at spec.correspondenceWhere
/// (else spec.where) naming the mesh file and what it found: a non-manifold edge, or meshes the
/// chosen correspondence does not apply to.
/// Interrupted when `interrupter` asks to stop (between the merges, and inside the spherical map).
Corresponded correspond(const Mesh& source, const Mesh& target, const SurfaceSpec& spec,
                        Interrupter* interrupter = nullptr);

} // namespace volmorph::detail
