#include "StarMerge.h"

#include "Landmarks.h"
#include "MergeSide.h"
#include "SphereOverlay.h"

#include <Eigen/LU>

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

/// A side's vertices seen from `kernel` (unit directions), moved by `warp` (the landmarks').
std::vector<Vec3d> directions(const Side& s, const Vec3d& kernel, const SphereWarp& warp)
{
    std::vector<Vec3d> out;
    for (const Vec3d& p : s.points) {
        Vec3d d = p - kernel;
        d.normalize();
        out.push_back(warp(d));
    }
    return out;
}

/// The side on the sphere, turned by `turn`; nullopt when a triangle is not counter-clockwise
/// there (exact), its index in `turnedOver`.
std::optional<SphereTriangulation> project(const Side& s, const std::vector<Vec3d>& dirs,
                                           const Eigen::Matrix3d& turn, uint32_t& turnedOver)
{
    SphereTriangulation out;
    out.triangles = s.triangles;
    for (const Vec3d& d : dirs) out.directions.push_back(toGrid(turned(turn, d)));
    for (uint32_t j = 0; j < s.triangles.size(); ++j) {
        const Vec3I& t = s.triangles[j];
        if (orientation(out.directions[t[0]], out.directions[t[1]], out.directions[t[2]]) <= 0) {
            turnedOver = j;
            return std::nullopt;
        }
    }
    return out;
}

/// Where direction `dir` meets triangle `t` of `s`, whose corners are seen in directions `dirs`
/// from `kernel`: barycentric weights (with no landmarks, the ray from the kernel's). `onEdge`:
/// the point is on the edge (u, v), and the third weight is 0.
Eigen::Vector3d weights(const Side& s, const std::vector<Vec3d>& dirs, const Vec3I& t,
                        const Vec3d& kernel, const Vec3d& dir, const uint32_t* onEdge)
{
    Eigen::Matrix3d m;
    for (int c = 0; c < 3; ++c)
        m.col(c) = Eigen::Vector3d(dirs[t[c]].x(), dirs[t[c]].y(), dirs[t[c]].z());
    Eigen::Vector3d k = m.partialPivLu().solve(Eigen::Vector3d(dir.x(), dir.y(), dir.z()));
    for (int c = 0; c < 3; ++c) k(c) /= (s.points[t[c]] - kernel).length();
    if (onEdge)
        for (int c = 0; c < 3; ++c)
            if (t[c] != onEdge[0] && t[c] != onEdge[1]) k(c) = 0.0;
    return k / k.sum();
}

/// The merged vertex `v` on side `s` (world units) and its colour there.
void place(const Side& s, const std::vector<Vec3d>& dirs, const Vec3d& kernel,
           const OverlayVertex& v, bool isSource, const Vec3d& dir, Vec3d& at, Vec3f* color)
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
        weights(s, dirs, t, kernel, dir, v.kind == OverlayVertex::Kind::Crossing ? ends : nullptr);
    at = w(0) * s.points[t[0]] + w(1) * s.points[t[1]] + w(2) * s.points[t[2]];
    if (color) *color = Vec3f(w(0) * rgb(t[0]) + w(1) * rgb(t[1]) + w(2) * rgb(t[2]));
}

std::string edgeOn(const Side& s, const Vec3d& kernel, uint32_t triangle)
{
    return s.mesh->file.string() + ": triangle " + std::to_string(triangle) +
           " is seen edge-on from " + pointText(kernel) + " (too thin to project)";
}

} // namespace

namespace {

/// The target's landmarks made vertices, and the warp of its sphere that takes each onto the
/// source's landmark there.
SphereWarp landmarkWarp(const Side& a, const Vec3d& ka, Side& b, const Vec3d& kb,
                        const std::vector<SurfaceLandmark>& landmarks)
{
    std::vector<Vec3d> from, to;
    for (const MergeSide::Place& p : snapLandmarks(a, landmarks, true)) {
        Vec3d d = p.point - ka;
        to.push_back(d / d.length());
    }
    snapLandmarks(b, landmarks, false); // the checks; each is placed once the last is in
    for (const SurfaceLandmark& l : landmarks) {
        Vec3d d = b.points[b.insert(b.nearest(l.target))] - kb;
        from.push_back(d / d.length());
    }
    return SphereWarp(from, to);
}

} // namespace

Corresponded starMerge(const Mesh& source, const Mesh& target,
                       const std::optional<std::pair<Vec3d, Vec3d>>& kernels,
                       const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where)
{
    Side a(source), b(target);
    const KernelPoint ka =
        kernelOf(a, kernels ? std::optional<Vec3d>(kernels->first) : std::nullopt);
    const KernelPoint kb =
        kernelOf(b, kernels ? std::optional<Vec3d>(kernels->second) : std::nullopt);
    requireStarShaped(a, ka, kernels.has_value(), where);
    requireStarShaped(b, kb, kernels.has_value(), where);
    const SphereWarp warp = landmarkWarp(a, ka.point, b, kb.point, landmarks);
    const std::vector<Vec3d> da = directions(a, ka.point, SphereWarp({}, {}));
    const std::vector<Vec3d> db = directions(b, kb.point, warp);
    uint32_t bad = 0;
    const std::optional<SphereTriangulation> sa = project(a, da, Eigen::Matrix3d::Identity(), bad);
    if (!sa) throw UserError(where, edgeOn(a, ka.point, bad));
    // A vertex of one exactly on an edge of the other leaves regions without area, which the
    // turn removes; if an attempt still leaves one (a vertex on the turn's axis), another axis.
    Overlay merged;
    Eigen::Matrix3d rotation;
    size_t folded = 0;
    for (int attempt = 0; attempt < kMergeAttempts; ++attempt) {
        rotation = mergeTurn(attempt);
        const std::optional<SphereTriangulation> sb = project(b, db, rotation, bad);
        if (!sb && landmarks.empty()) throw UserError(where, edgeOn(b, kb.point, bad));
        if (!sb)
            throw UserError(landmarks.front().where,
                            "[[pair]]: the landmarks (" + landmarkPlaces(landmarks) +
                                ") turn triangle " + std::to_string(bad) + " of " +
                                target.file.string() +
                                " over on the sphere: they cannot meet without folding the map");
        merged = overlay(*sa, *sb);
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
    placeMergedVertices(out, merged.vertices.size(), source.hasColors() || target.hasColors(),
                        [&](size_t v, bool isSource, Vec3d& at, Vec3f* color) {
                            const Vec3d& dir = merged.directions[v];
                            if (isSource)
                                place(a, da, ka.point, merged.vertices[v], true, dir, at, color);
                            else
                                place(b, db, kb.point, merged.vertices[v], false,
                                      turned(rotation.transpose(), dir), at, color);
                        });
    return out;
}

} // namespace volmorph::detail
