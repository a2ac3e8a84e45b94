// One input of a merged correspondence (Kent's star merge, the disk merge) as the merge sees it:
// the vertices its triangles use, in double precision, with their colours.
#pragma once

#include <volmorph/Mesh.h>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace volmorph::detail {

struct MergeSide {
    const Mesh* mesh = nullptr;
    std::vector<Vec3d> points;      ///< world units
    std::vector<Vec3I> triangles;   ///< into `points`
    std::vector<uint32_t> original; ///< per vertex, its index in the mesh
    double diagonal = 1.0;          ///< of the mesh's bounds, world units

    /// The used vertices in the mesh's order (all of them, for a mesh without strays: then the
    /// merged mesh's first vertices are the mesh's own, in its order).
    explicit MergeSide(const Mesh& m);

    /// Vertex v's colour, grey (Voxelize.cpp's) when the mesh has none.
    Vec3d color(uint32_t v) const
    {
        return mesh->hasColors() ? Vec3d(mesh->colors[original[v]]) : Vec3d(0.8);
    }
    /// `mesh` with only the used vertices (for the maps that take a Mesh).
    Mesh compacted() const;
};

/// The turn of the target's sphere for a merge attempt: a millionth of a radian about an axis of
/// no symmetry (another for each attempt), so that no vertex of one side lies exactly on a vertex
/// or edge of the other (which would leave regions without area).
Eigen::Matrix3d mergeTurn(int attempt);
Vec3d turned(const Eigen::Matrix3d& m, const Vec3d& v);

/// "(x, y, z)" with six significant digits, for messages.
std::string pointText(const Vec3d& p);

} // namespace volmorph::detail
