// Kent, Carlson and Parent 1992, "Shape transformation for polyhedral objects": two star-shaped
// meshes of genus 0, each projected onto the unit sphere from a point of its kernel (one-to-one and
// continuous for a star-shaped mesh), the two spherical networks merged (SphereOverlay.h), and the
// merged network mapped back onto both surfaces by the same projections: one connectivity, each
// vertex with a place on each surface. Vertex colours follow through barycentric coordinates.
//
// A vertex of one mesh exactly on an edge or vertex of the other (a sphere's pole on a cube face's
// diagonal) leaves regions without area; the merge is then made again with the target's sphere
// turned by a millionth of a radian about an axis of no symmetry (MergeSide.h's mergeTurn). The
// places on the surfaces are unaffected (each side is mapped back through its own projection);
// the correspondence moves by a millionth of the radius.
#pragma once

#include "Correspondence.h"
#include "StarKernel.h"

namespace volmorph::detail {

/// Kent's merge of `source` and `target` (closed, genus 0, outward-facing), projected from
/// `kernels` (world units) when given, else from each mesh's deepest kernel point. Each landmark's
/// target point becomes a vertex of the target, and the target's sphere is warped (SphereWarp) so
/// that it meets the source's point; a landmark off its surface, or landmarks that would turn a
/// triangle over, are refused at their pair. Throws
/// UserError at `where` naming the mesh when it is not star-shaped from the given point (the
/// message starts "surface.kernel: ") or from any (a triangle seen from behind and its vertex that
/// cannot be seen; the message starts with the mesh file), or when the merge leaves a triangle
/// without area on the sphere after every turn.
Corresponded starMerge(const Mesh& source, const Mesh& target,
                       const std::optional<std::pair<Vec3d, Vec3d>>& kernels,
                       const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where);

} // namespace volmorph::detail
