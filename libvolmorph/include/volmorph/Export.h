// In-betweens as meshes, for Houdini, Blender or any mesh tool.
#pragma once

#include <volmorph/Mesh.h>
#include <volmorph/SurfaceMorph.h>
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

/// Writes a surface morph's frame, chosen by the extension: binary little-endian PLY with float x
/// y z, the vertex velocity as float vx vy vz (as `frame.velocity` holds it: the command line
/// writes world units per second), and colours as uchar red green blue alpha (linear values times
/// 255, as Assimp writes them) when the frame has colours; or OBJ (positions and triangles, no
/// velocity). The file appears at `path` only when complete; UserError naming the path otherwise.
void writeSurfaceFrame(const SurfaceFrame& frame, const std::filesystem::path& path);

} // namespace volmorph
