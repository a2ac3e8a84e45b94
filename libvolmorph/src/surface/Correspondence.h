// Correspondence: two meshes become one connectivity with a place on each surface. What exists
// today is the identity (the same vertices and triangles); Kent's star-shaped merge, the spherical
// and the disk parameterizations are named by the scene's keys and refused until they exist.
#pragma once

#include <volmorph/Mesh.h>
#include <volmorph/SurfaceSettings.h>

namespace volmorph::detail {

/// The two sides on one connectivity: source.triangles == target.triangles, vertex i of each is
/// the same point of the correspondence.
struct Corresponded {
    Mesh source, target;
    Correspondence used = Correspondence::Identity;
};

/// Why the identity does not apply to these meshes ("" when it does).
std::string identityMismatch(const Mesh& source, const Mesh& target);

/// Puts the meshes into correspondence as `spec` says. Throws UserError at spec.correspondenceWhere
/// (else spec.where) naming the mesh file and what it found: a non-manifold edge, or meshes the
/// chosen correspondence does not apply to.
Corresponded correspond(Mesh source, Mesh target, const SurfaceSpec& spec);

} // namespace volmorph::detail
