// Hole filling: each boundary loop of a mesh is closed by a patch that continues the surface
// around it, as Liepa ("Filling holes in meshes", SGP 2003) fairs his: the patch's vertices
// minimize the thin-plate energy, the sum of squared umbrella Laplacians over the patch and its
// rim, where a rim vertex's Laplacian also reaches its neighbours in the mesh. The patch thus meets
// the mesh with continuous tangent planes, and a sphere's missing cap comes back round, not flat.
#pragma once

#include <volmorph/Mesh.h>

#include <cstddef>

namespace volmorph::detail {

struct HoleFillStats {
    size_t holes = 0;          ///< boundary loops closed
    size_t unclosed = 0;       ///< boundary chains that did not close into a loop (left open)
    size_t patchTriangles = 0; ///< triangles added
};

/// Closes every boundary loop of `mesh` (consistently oriented, as repairOrientation leaves it; a
/// boundary walk that passes a vertex twice is split there into loops patched apart)
/// with a faired patch whose edges are about `spacing` world units long, or the loop's own mean
/// edge length when that is longer. New vertices take colours faired like their positions. The
/// topology report is refreshed.
HoleFillStats fillHoles(Mesh& mesh, double spacing);

} // namespace volmorph::detail
