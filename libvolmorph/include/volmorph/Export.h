// In-betweens as meshes, for Houdini, Blender or any mesh tool.
#pragma once

#include <volmorph/Mesh.h>
#include <volmorph/VolumeSet.h>

#include <filesystem>

namespace volmorph {

/// The surface of a VolumeSet as a triangle mesh in world units, facing outward: the zero set of
/// its sdf when it has one, else the 0.5 isosurface of its density (OpenVDB's volumeToMesh, quads
/// split into triangles). Vertex colours are its Cd grid sampled at the vertices.
Mesh surfaceMesh(const VolumeSet& volumes, double adaptivity = 0.0);

/// Writes `mesh` as PLY (ASCII, with vertex colours) or OBJ (no material file), chosen by the
/// extension, through Assimp's exporter. The file appears at `path` only when complete. Throws
/// UserError naming the path when it cannot be written or the extension is neither.
void writeMesh(const Mesh& mesh, const std::filesystem::path& path);

} // namespace volmorph
