// Generalized winding number of a triangle soup (Jacobson, Kavan and Sorkine-Hornung 2013),
// evaluated in O(log n) per query with a bounding-volume hierarchy whose far clusters are replaced
// by their first-order (dipole) expansion (Barill, Dickson, Schmidt, Levin and Jacobson 2018).
#pragma once

#include <volmorph/Mesh.h>

#include <vector>

namespace volmorph::detail {

class WindingNumber {
public:
    /// Keeps a reference to `points`; `triangles` are copied (optionally a subset).
    WindingNumber(const std::vector<Vec3f>& points, std::vector<Vec3I> triangles);

    /// w(p): 1 inside a closed, outward-oriented surface, 0 outside, fractional near holes.
    double operator()(const Vec3d& p) const;

    /// Exact sum over every triangle, O(n): the reference the tests compare against.
    double exact(const Vec3d& p) const;

private:
    struct Node {
        Vec3d center{0.0}; ///< area-weighted centroid of the node's triangles
        Vec3d areaNormal{
            0.0};          ///< sum of the triangles' area-weighted normals (half cross products)
        double radius = 0; ///< every vertex of the node lies within radius of center
        uint32_t first = 0, count = 0; ///< triangle range, for leaves
        uint32_t left = 0, right = 0;  ///< children, for inner nodes (count == 0)
    };

    uint32_t build(uint32_t first, uint32_t count);
    double solidAngle(const Vec3I& tri, const Vec3d& p) const;

    const std::vector<Vec3f>* mPoints;
    std::vector<Vec3I> mTriangles;
    std::vector<Node> mNodes;
};

} // namespace volmorph::detail
