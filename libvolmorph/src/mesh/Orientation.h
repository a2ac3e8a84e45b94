// Orientation repair: meshes from scans and exports often mix inward and outward triangles, and
// the winding number (and OpenVDB's meshToVolume) need them outward.
#pragma once

#include <volmorph/Mesh.h>

#include <cstddef>

namespace volmorph::detail {

/// Makes each connected shell's triangle orientation consistent (the majority orientation of the
/// shell wins across manifold edges), then flips shells of negative volume that lie inside no
/// other shell. Returns the number of triangles flipped; the topology report is refreshed.
size_t repairOrientation(Mesh& mesh);

} // namespace volmorph::detail
