#include "SphereSides.h"

#include "SphereOverlay.h"

#include <Eigen/LU>

namespace volmorph::detail {
namespace {

/// The side on the sphere, turned by `turn`; nullopt when a triangle is not counter-clockwise
/// there (exact), its index in `turnedOver`.
std::optional<SphereTriangulation> project(const SphereSide& s, const Eigen::Matrix3d& turn,
                                           uint32_t& turnedOver)
{
    SphereTriangulation out;
    out.triangles = s.side->triangles;
    for (const Vec3d& d : s.directions) out.directions.push_back(toGrid(turned(turn, d)));
    for (uint32_t j = 0; j < out.triangles.size(); ++j) {
        const Vec3I& t = out.triangles[j];
        if (orientation(out.directions[t[0]], out.directions[t[1]], out.directions[t[2]]) <= 0) {
            turnedOver = j;
            return std::nullopt;
        }
    }
    return out;
}

/// Where direction `dir` falls in triangle `t` of `s`: barycentric weights of the point of the
/// triangle's chord plane in that direction, each over its corner's depth (for a star, the ray
/// from the kernel). `onEdge`: the point is on the edge (u, v), and the third weight is 0.
Eigen::Vector3d weights(const SphereSide& s, const Vec3I& t, const Vec3d& dir,
                        const uint32_t* onEdge)
{
    Eigen::Matrix3d m;
    for (int c = 0; c < 3; ++c) {
        const Vec3d& d = s.directions[t[c]];
        m.col(c) = Eigen::Vector3d(d.x(), d.y(), d.z());
    }
    Eigen::Vector3d k = m.partialPivLu().solve(Eigen::Vector3d(dir.x(), dir.y(), dir.z()));
    for (int c = 0; c < 3; ++c) k(c) /= s.depth[t[c]];
    if (onEdge)
        for (int c = 0; c < 3; ++c)
            if (t[c] != onEdge[0] && t[c] != onEdge[1]) k(c) = 0.0;
    return k / k.sum();
}

/// The merged vertex `v` on side `s` (world units) and its colour there.
void place(const SphereSide& side, const OverlayVertex& v, bool isSource, const Vec3d& dir,
           Vec3d& at, Vec3f* color)
{
    const MergeSide& s = *side.side;
    if (placeOwnVertex(s, v, isSource, at, color)) return;
    const uint32_t* ends = isSource ? v.source : v.target;
    const Vec3I& t = s.triangles[isSource ? v.sourceTriangle : v.targetTriangle];
    const Eigen::Vector3d w =
        weights(side, t, dir, v.kind == OverlayVertex::Kind::Crossing ? ends : nullptr);
    at = w(0) * s.points[t[0]] + w(1) * s.points[t[1]] + w(2) * s.points[t[2]];
    if (color) *color = Vec3f(w(0) * s.color(t[0]) + w(1) * s.color(t[1]) + w(2) * s.color(t[2]));
}

} // namespace

bool placeOwnVertex(const MergeSide& s, const OverlayVertex& v, bool isSource, Vec3d& at,
                    Vec3f* color)
{
    const OverlayVertex::Kind own =
        isSource ? OverlayVertex::Kind::Source : OverlayVertex::Kind::Target;
    if (v.kind != own) return false;
    const uint32_t vertex = isSource ? v.source[0] : v.target[0];
    at = s.points[vertex];
    if (color) *color = Vec3f(s.color(vertex));
    return true;
}

Corresponded mergeSides(const SphereSide& a, const SphereSide& b, Correspondence used,
                        const TurnedOver& turnedOver, const SourceLocation& where)
{
    uint32_t bad = 0;
    const std::optional<SphereTriangulation> sa = project(a, Eigen::Matrix3d::Identity(), bad);
    if (!sa) turnedOver(true, bad);
    // A vertex of one exactly on an edge of the other leaves regions without area, which the
    // turn removes; if an attempt still leaves one (a vertex on the turn's axis), another axis.
    Overlay merged;
    Eigen::Matrix3d rotation;
    size_t folded = 0;
    for (int attempt = 0; attempt < kMergeAttempts; ++attempt) {
        rotation = mergeTurn(attempt);
        const std::optional<SphereTriangulation> sb = project(b, rotation, bad);
        if (!sb) turnedOver(false, bad);
        merged = overlay(*sa, *sb);
        folded = invertedTriangles(merged.grid, merged.triangles);
        if (folded == 0) break;
    }
    if (folded > 0)
        throw UserError(where, "merging " + a.side->mesh->file.string() + " and " +
                                   b.side->mesh->file.string() + " left " + std::to_string(folded) +
                                   " triangles without area on the sphere");
    Corresponded out;
    out.used = used;
    out.triangles = merged.triangles;
    out.crossings = merged.crossings;
    const bool colors = a.side->mesh->hasColors() || b.side->mesh->hasColors();
    placeMergedVertices(
        out, merged.vertices.size(), colors, [&](size_t v, bool isSource, Vec3d& at, Vec3f* color) {
            const Vec3d& dir = merged.directions[v];
            if (isSource)
                place(a, merged.vertices[v], true, dir, at, color);
            else
                place(b, merged.vertices[v], false, turned(rotation.transpose(), dir), at, color);
        });
    placeMergedUVs(out, merged.regions, *a.side, *b.side);
    return out;
}

} // namespace volmorph::detail
