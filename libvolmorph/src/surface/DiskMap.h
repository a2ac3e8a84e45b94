// The planar half of the disk correspondence (a mesh with one boundary loop, such as a face scan
// without the back of the head): a harmonic map onto the unit disk. The boundary loop's vertices
// are fixed on the unit circle, spaced by their arc length; each interior vertex is where the
// spring energy with cotangent weights is least (H_aa V_a = -H_ab V_b, free vertices a, fixed b:
// one sparse solve). Cotangent weights can be negative on obtuse triangles, and then the map can
// fold; when it does, the map is made again with Floater's mean value weights (2003), which are
// positive and give a one-to-one map onto a convex boundary (Tutte's theorem). Merging two such
// maps in the plane (the overlay of both meshes) is the disk correspondence's other half, not
// built.
#pragma once

#include <volmorph/Mesh.h>

#include <Eigen/Core>

#include <vector>

namespace volmorph::detail {

struct DiskMap {
    std::vector<Eigen::Vector2d> uv; ///< per vertex, in the closed unit disk
    std::vector<uint32_t> boundary;  ///< the loop's vertices in order
    bool meanValue = false;          ///< the cotangent map folded; these are mean value weights
};

/// The boundary loops of `mesh`: each a list of vertices in the order its boundary edges run.
/// Throws UserError at `where` naming the mesh when a vertex has two boundary edges leaving it
/// (the boundary touches itself).
std::vector<std::vector<uint32_t>> boundaryLoops(const Mesh& mesh, const SourceLocation& where);

/// The harmonic map of `mesh` onto the unit disk, counter-clockwise as the triangles face. Throws
/// UserError at `where` naming the mesh when it has no boundary loop or more than one, or more than
/// one connected piece.
DiskMap harmonicDiskMap(const Mesh& mesh, const SourceLocation& where);

/// The triangles whose image in the plane has no positive area (folded or degenerate).
size_t foldedTriangles(const Mesh& mesh, const std::vector<Eigen::Vector2d>& uv);

} // namespace volmorph::detail
