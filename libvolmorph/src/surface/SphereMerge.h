// The `sphere` correspondence: two closed genus-0 meshes, star-shaped or not, each mapped onto the
// unit sphere by its progressive-mesh parameterization (SphereParam.h, Praun and Hoppe 2003), the
// target's map warped so its landmarks land on the source's, and the two spherical triangulations
// merged as Kent's are (SphereSides.h): one connectivity, each vertex on both surfaces.
#pragma once

#include "Correspondence.h"

#include <volmorph/core/Interrupter.h>

namespace volmorph::detail {

/// The merge of `source` and `target` (closed, genus 0, one piece, outward-facing). Each
/// landmark's target point becomes a vertex of the target before its map is made. Throws
/// UserError at `where` naming the mesh when it does not simplify to a tetrahedron, at a
/// landmark's pair when it is off its surface or the landmarks would turn a triangle over;
/// Interrupted when `interrupter` asks to stop.
Corresponded sphereMerge(const Mesh& source, const Mesh& target,
                         const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where,
                         Interrupter* interrupter = nullptr);

} // namespace volmorph::detail
