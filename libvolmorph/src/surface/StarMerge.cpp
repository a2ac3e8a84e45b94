#include "StarMerge.h"

#include "MergeSide.h"
#include "SphereOverlay.h"

#include <Eigen/LU>
#include <tbb/parallel_for.h>

#include <stdexcept>

namespace volmorph::detail {
namespace {

using Side = MergeSide;

KernelPoint kernelOf(const Side& s, const std::optional<Vec3d>& given)
{
    return given ? kernelDepth(s.points, s.triangles, *given)
                 : deepestKernelPoint(s.points, s.triangles);
}

void requireStarShaped(const Side& s, const KernelPoint& k, bool given, const SourceLocation& where)
{
    if (k.margin > 1e-9 * s.diagonal) return;
    const Vec3I& t = s.triangles[k.worstTriangle];
    const std::string face =
        "triangle " + std::to_string(k.worstTriangle) + " (vertices " +
        std::to_string(s.original[t[0]]) + ", " + std::to_string(s.original[t[1]]) + ", " +
        std::to_string(s.original[t[2]]) + ") faces away from it, so vertex " +
        std::to_string(s.original[t[0]]) + " at " + pointText(s.points[t[0]]) + " cannot be seen";
    if (given)
        throw UserError(where, "surface.kernel: " + s.mesh->file.string() +
                                   " is not seen whole from " + pointText(k.point) + ": " + face);
    throw UserError(
        where, s.mesh->file.string() +
                   " is not star-shaped: no point sees all of its surface (from " +
                   pointText(k.point) + ", the point nearest to it, " + face +
                   "); the spherical map (correspondence = \"sphere\", not in this version yet) "
                   "will map any closed genus-0 mesh");
}

SphereTriangulation project(const Side& s, const Vec3d& kernel, const Eigen::Matrix3d& turn,
                            const SourceLocation& where)
{
    SphereTriangulation out;
    out.triangles = s.triangles;
    for (const Vec3d& p : s.points) {
        Vec3d d = p - kernel;
        d.normalize();
        out.directions.push_back(toGrid(turned(turn, d)));
    }
    for (uint32_t j = 0; j < s.triangles.size(); ++j) {
        const Vec3I& t = s.triangles[j];
        if (orientation(out.directions[t[0]], out.directions[t[1]], out.directions[t[2]]) <= 0)
            throw UserError(where, s.mesh->file.string() + ": triangle " + std::to_string(j) +
                                       " is seen edge-on from " + pointText(kernel) +
                                       " (too thin to project); correspondence = \"sphere\"");
    }
    return out;
}

/// Where direction `dir` (from `kernel`) meets triangle `t` of `s`: barycentric weights. `onEdge`:
/// the point is on the edge (u, v), and the third weight is 0.
Eigen::Vector3d weights(const Side& s, const Vec3I& t, const Vec3d& kernel, const Vec3d& dir,
                        const uint32_t* onEdge)
{
    Eigen::Matrix3d m;
    for (int c = 0; c < 3; ++c) {
        const Vec3d e = s.points[t[c]] - kernel;
        m.col(c) = Eigen::Vector3d(e.x(), e.y(), e.z());
    }
    Eigen::Vector3d k = m.partialPivLu().solve(Eigen::Vector3d(dir.x(), dir.y(), dir.z()));
    if (onEdge)
        for (int c = 0; c < 3; ++c)
            if (t[c] != onEdge[0] && t[c] != onEdge[1]) k(c) = 0.0;
    return k / k.sum();
}

/// The merged vertex `v` on side `s` (world units) and its colour there.
void place(const Side& s, const Vec3d& kernel, const OverlayVertex& v, bool isSource,
           const Vec3d& dir, Vec3d& at, Vec3f* color)
{
    const OverlayVertex::Kind own =
        isSource ? OverlayVertex::Kind::Source : OverlayVertex::Kind::Target;
    const uint32_t* ends = isSource ? v.source : v.target;
    const auto rgb = [&](uint32_t i) { return s.color(i); };
    if (v.kind == own) {
        at = s.points[ends[0]];
        if (color) *color = Vec3f(rgb(ends[0]));
        return;
    }
    const Vec3I& t = s.triangles[isSource ? v.sourceTriangle : v.targetTriangle];
    const Eigen::Vector3d w =
        weights(s, t, kernel, dir, v.kind == OverlayVertex::Kind::Crossing ? ends : nullptr);
    at = w(0) * s.points[t[0]] + w(1) * s.points[t[1]] + w(2) * s.points[t[2]];
    if (color) *color = Vec3f(w(0) * rgb(t[0]) + w(1) * rgb(t[1]) + w(2) * rgb(t[2]));
}

} // namespace

std::pair<KernelPoint, KernelPoint>
starKernels(const Mesh& source, const Mesh& target,
            const std::optional<std::pair<Vec3d, Vec3d>>& kernels)
{
    const Side a(source), b(target);
    return {kernelOf(a, kernels ? std::optional<Vec3d>(kernels->first) : std::nullopt),
            kernelOf(b, kernels ? std::optional<Vec3d>(kernels->second) : std::nullopt)};
}

Corresponded starMerge(const Mesh& source, const Mesh& target,
                       const std::optional<std::pair<Vec3d, Vec3d>>& kernels,
                       const SourceLocation& where)
{
    const Side a(source), b(target);
    const KernelPoint ka =
        kernelOf(a, kernels ? std::optional<Vec3d>(kernels->first) : std::nullopt);
    const KernelPoint kb =
        kernelOf(b, kernels ? std::optional<Vec3d>(kernels->second) : std::nullopt);
    requireStarShaped(a, ka, kernels.has_value(), where);
    requireStarShaped(b, kb, kernels.has_value(), where);
    // A vertex of one exactly on an edge of the other leaves regions without area, which the
    // turn removes; if an attempt still leaves one (a vertex on the turn's axis), another axis.
    const SphereTriangulation sa = project(a, ka.point, Eigen::Matrix3d::Identity(), where);
    Overlay merged;
    Eigen::Matrix3d rotation;
    size_t folded = 0;
    for (int attempt = 0; attempt < 3; ++attempt) {
        rotation = mergeTurn(attempt);
        merged = overlay(sa, project(b, kb.point, rotation, where));
        folded = invertedTriangles(merged.grid, merged.triangles);
        if (folded == 0) break;
    }
    if (folded > 0)
        throw UserError(where, "merging " + source.file.string() + " and " + target.file.string() +
                                   " left " + std::to_string(folded) +
                                   " triangles without area on the sphere");
    Corresponded out;
    out.used = Correspondence::Star;
    out.triangles = merged.triangles;
    out.crossings = merged.crossings;
    out.kernels = std::pair{ka.point, kb.point};
    const size_t n = merged.vertices.size();
    out.source.resize(n);
    out.target.resize(n);
    const bool colors = source.hasColors() || target.hasColors();
    if (colors) {
        out.sourceColors.resize(n);
        out.targetColors.resize(n);
    }
    tbb::parallel_for(size_t(0), n, [&](size_t v) {
        const OverlayVertex& o = merged.vertices[v];
        const Vec3d& dir = merged.directions[v];
        place(a, ka.point, o, true, dir, out.source[v], colors ? &out.sourceColors[v] : nullptr);
        place(b, kb.point, o, false, turned(rotation.transpose(), dir), out.target[v],
              colors ? &out.targetColors[v] : nullptr);
    });
    return out;
}

} // namespace volmorph::detail
