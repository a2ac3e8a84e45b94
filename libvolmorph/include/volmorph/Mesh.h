// Triangle meshes imported from files (Assimp: OBJ, PLY, STL, OFF, glTF and the rest it reads),
// welded, placed in the world and checked.
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>
#include <volmorph/core/ObjectTransform.h>

#include <openvdb/math/Vec3.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace volmorph {

/// What import found and repaired. Nothing here is fatal: open and non-manifold meshes are common
/// in the wild and the voxelizer handles them.
struct MeshReport {
    size_t inputTriangles = 0;      ///< after triangulation, before clean-up
    size_t degenerateTriangles = 0; ///< dropped: repeated vertex or zero area
    size_t duplicateVertices = 0;   ///< welded: identical positions merged
    size_t boundaryEdges = 0;       ///< edges used by one triangle (holes)
    size_t nonManifoldEdges = 0;    ///< edges used by three or more triangles
    size_t misorientedEdges = 0;    ///< edges whose two triangles traverse them the same way
    size_t components = 0;          ///< connected shells (by shared vertices)

    bool watertight() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
    bool consistentlyOriented() const { return misorientedEdges == 0; }
};

/// An indexed triangle mesh in world units.
struct Mesh {
    std::vector<Vec3f> points;
    std::vector<Vec3I> triangles;
    std::vector<Vec3f> colors; ///< per vertex, linear RGB; empty when the file has none
    /// Per triangle corner (3 per triangle, in `triangles`' order), the file's first set of texture
    /// coordinates (u, v): a seam's vertices stay welded, each triangle keeps its own. Empty when
    /// the file has none (and after code that adds triangles without them, such as hole filling).
    std::vector<Vec2f> uvs;
    MeshReport report;
    std::filesystem::path file;

    bool hasColors() const { return !colors.empty(); }
    bool hasUVs() const { return !uvs.empty() && uvs.size() == 3 * triangles.size(); }
    /// Axis-aligned bounds of the points; {+inf, -inf} for an empty mesh.
    std::pair<Vec3d, Vec3d> bounds() const;
};

/// Imports every triangle of a mesh file, applies `transform`, welds identical positions, drops and
/// counts degenerate triangles, and fills the report.
/// Throws UserError naming the file when it cannot be read, is not a mesh, has no triangles
/// or has a non-finite coordinate. `where` is reported with the error (e.g. the scene's `mesh`
/// key); when its file is empty the mesh file itself is named.
Mesh importMesh(const std::filesystem::path& file, const ObjectTransform& transform = {},
                const SourceLocation& where = {});

/// Recomputes the topology part of the report (edges, orientation, components) for `mesh`.
void analyzeTopology(Mesh& mesh);

} // namespace volmorph
