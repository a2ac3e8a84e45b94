// One input of a merged correspondence (Kent's star merge, the disk merge) as the merge sees it:
// the vertices its triangles use, in double precision, with their colours.
#pragma once

#include "Correspondence.h"

#include <volmorph/Mesh.h>

#include <Eigen/Core>
#include <tbb/parallel_for.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace volmorph::detail {

struct MergeSide {
    const Mesh* mesh = nullptr;
    std::vector<Vec3d> points;      ///< world units
    std::vector<Vec3I> triangles;   ///< into `points`
    std::vector<uint32_t> original; ///< per vertex, its index in the mesh (kNone: inserted)
    std::vector<Vec3d> colors;      ///< per vertex, linear RGB (grey when the mesh has none)
    /// Per triangle, its corners' texture coordinates; empty when the mesh has none.
    std::vector<std::array<Vec2d, 3>> uvs;
    double diagonal = 1.0; ///< of the mesh's bounds, world units

    static constexpr uint32_t kNone = ~0u;

    /// The used vertices in the mesh's order (all of them, for a mesh without strays: then the
    /// merged mesh's first vertices are the mesh's own, in its order).
    explicit MergeSide(const Mesh& m);

    Vec3d color(uint32_t v) const { return colors[v]; }
    /// The texture coordinates of point `p` (on triangle `triangle`, world units) by its
    /// barycentric weights there; of the nearest point of the surface when `triangle` is not one
    /// of the side's (a disk's cap). (0, 0) when the mesh has none.
    Vec2d uvAt(uint32_t triangle, const Vec3d& p) const;
    /// The used vertices (and any inserted), as a Mesh for the maps that take one.
    Mesh compacted() const;

    /// The nearest point of the surface to `p`: its triangle and barycentric weights there.
    struct Place {
        uint32_t triangle = 0;
        Vec3d weights;
        Vec3d point;
        double distance = 0.0;
    };
    Place nearest(const Vec3d& p) const;
    /// Makes `at` a vertex, splitting its triangle (or the edge it lies on; a vertex it is at is
    /// returned as it is), the surface unchanged. Returns the vertex.
    uint32_t insert(const Place& at);
};

/// The turn of the target's sphere for a merge attempt (kMergeAttempts): none at first, so that
/// landmarks meet exactly; then, when a vertex of one side lies exactly on a vertex or edge of the
/// other (which leaves regions without area), a millionth of a radian about an axis of no
/// symmetry, another for each attempt.
inline constexpr int kMergeAttempts = 4;
Eigen::Matrix3d mergeTurn(int attempt);
Vec3d turned(const Eigen::Matrix3d& m, const Vec3d& v);

/// Sizes `out`'s two sides (and their colours when `colors`) for `n` merged vertices and fills
/// vertex i of each with place(i, isSource, point, colour or null), in parallel (per index: the
/// same bits at any thread count).
template <typename Place>
void placeMergedVertices(Corresponded& out, size_t n, bool colors, Place&& place)
{
    out.source.resize(n);
    out.target.resize(n);
    if (colors) {
        out.sourceColors.resize(n);
        out.targetColors.resize(n);
    }
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        place(i, true, out.source[i], colors ? &out.sourceColors[i] : nullptr);
        place(i, false, out.target[i], colors ? &out.targetColors[i] : nullptr);
    });
}

/// Fills `out`'s texture coordinates from `a` (source) and `b` (target) when either has them:
/// each merged triangle's corners at their places on each side, in the side's triangle its region
/// lies in (`regions`, per merged triangle). Needs out.source, out.target and out.triangles.
void placeMergedUVs(Corresponded& out, const std::vector<std::pair<uint32_t, uint32_t>>& regions,
                    const MergeSide& a, const MergeSide& b);

/// "(x, y, z)" with six significant digits, for messages.
std::string pointText(const Vec3d& p);

} // namespace volmorph::detail
