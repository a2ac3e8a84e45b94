#include "DiskMerge.h"

#include "DiskMap.h"
#include "Landmarks.h"
#include "MergeSide.h"
#include "SphereOverlay.h"
#include "SphereSides.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// One side's disk map, turned by `turn` radians, and its boundary.
struct Disk {
    std::vector<Eigen::Vector2d> uv;
    std::vector<uint32_t> boundary;
    double turn = 0.0; ///< about the disk's centre, radians
    /// then the lifted sphere's turn (the merge's tie breaker)
    Eigen::Matrix3d sphere = Eigen::Matrix3d::Identity();
};

Eigen::Vector2d rotate(const Eigen::Vector2d& p, double angle)
{
    const double c = std::cos(angle), s = std::sin(angle);
    return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

/// The boundary's points about their mean, and their angles on the circle.
void boundaryShape(const MergeSide& s, const Disk& d, std::vector<Vec3d>& points,
                   std::vector<double>& angles)
{
    Vec3d mean(0.0);
    for (uint32_t v : d.boundary) mean += s.points[v];
    mean /= double(d.boundary.size());
    for (uint32_t v : d.boundary) {
        points.push_back(s.points[v] - mean);
        angles.push_back(std::atan2(d.uv[v].y(), d.uv[v].x()));
    }
}

/// `turn` moved by at most a quarter of a degree so that the two loops' vertices are as far apart
/// on the circle as they can be: loops spaced alike would otherwise put vertices on vertices and
/// edges on edges (regions without area), which the merge's tie-breaking turn would then separate
/// by a millionth only, landmarks included. `a` are the source's angles, `b` the target's sorted.
double apart(const std::vector<double>& a, const std::vector<double>& b, double turn)
{
    auto separation = [&](double phi) {
        double least = kPi;
        for (double angle : a) {
            const double x = std::remainder(angle - phi, 2.0 * kPi);
            const size_t hi = size_t(std::lower_bound(b.begin(), b.end(), x) - b.begin());
            for (size_t k : {hi % b.size(), (hi + b.size() - 1) % b.size()})
                least = std::min(least, std::abs(std::remainder(x - b[k], 2.0 * kPi)));
        }
        return least;
    };
    double best = -1.0, out = turn;
    for (int k = -50; k <= 50; ++k) {
        const double phi = turn + kPi / 720.0 * k / 50.0;
        if (const double sep = separation(phi); sep > best) {
            best = sep;
            out = phi;
        }
    }
    return out;
}

/// The turn of b's disk that puts b's boundary nearest a's: least squares over the source's
/// boundary points against the target's boundary at the same angle (interpolated along its loop).
double bestTurn(const MergeSide& a, const Disk& da, const MergeSide& b, const Disk& db)
{
    std::vector<Vec3d> pa, pb;
    std::vector<double> ta, tb;
    boundaryShape(a, da, pa, ta);
    boundaryShape(b, db, pb, tb);
    // b's loop by increasing angle, for the lookup.
    std::vector<size_t> order(tb.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return tb[x] < tb[y]; });
    std::vector<double> sorted;
    for (size_t i : order) sorted.push_back(tb[i]);
    auto at = [&](double angle) {
        angle = std::remainder(angle, 2.0 * kPi);
        const size_t hi =
            size_t(std::lower_bound(sorted.begin(), sorted.end(), angle) - sorted.begin());
        const size_t i1 = order[hi % order.size()],
                     i0 = order[(hi + order.size() - 1) % order.size()];
        double span = tb[i1] - tb[i0], off = angle - tb[i0];
        if (span <= 0.0) span += 2.0 * kPi;
        if (off < 0.0) off += 2.0 * kPi;
        const double w = span > 0.0 ? std::clamp(off / span, 0.0, 1.0) : 0.0;
        return (1.0 - w) * pb[i0] + w * pb[i1];
    };
    double best = std::numeric_limits<double>::infinity(), turn = 0.0;
    for (int k = 0; k < 720; ++k) {
        const double phi = 2.0 * kPi * k / 720.0;
        double cost = 0.0;
        for (size_t i = 0; i < pa.size(); ++i) cost += (pa[i] - at(ta[i] - phi)).lengthSqr();
        if (cost < best) {
            best = cost;
            turn = phi;
        }
    }
    return apart(ta, sorted, turn);
}

/// The side's disk lifted onto the sphere (gnomonic) and closed by a cap: its vertices, then the
/// south pole; its triangles, then one cap triangle per boundary edge (in the loop's order).
SphereTriangulation lift(const MergeSide& s, const Disk& d, const Vec3d& pole)
{
    SphereTriangulation out;
    for (const Eigen::Vector2d& p : d.uv) {
        const Eigen::Vector2d q = rotate(p, d.turn);
        Vec3d dir(q.x(), q.y(), 1.0);
        dir.normalize();
        out.directions.push_back(toGrid(turned(d.sphere, dir)));
    }
    const uint32_t south = uint32_t(out.directions.size());
    out.directions.push_back(toGrid(pole));
    out.triangles = s.triangles;
    // The loop runs as its triangles' edges do, the disk on its left (counter-clockwise): the
    // cap is on the right.
    for (size_t k = 0; k < d.boundary.size(); ++k)
        out.triangles.emplace_back(d.boundary[(k + 1) % d.boundary.size()], d.boundary[k], south);
    return out;
}

Disk diskOf(const MergeSide& s, const SourceLocation& where)
{
    const DiskMap map = harmonicDiskMap(s.compacted(), where);
    Disk d;
    d.uv = map.uv;
    d.boundary = map.boundary;
    return d;
}

/// The place of merged vertex `v` (direction `dir` on the sphere) on side `s`: world position and
/// colour, from its triangle there (planar barycentric weights in the side's disk) or, in the
/// side's cap, the point of the cap's boundary edge on the ray from the disk's centre.
void place(const MergeSide& s, const Disk& d, const OverlayVertex& v, bool isSource,
           const Vec3d& dir, Vec3d& at, Vec3f* color)
{
    if (placeOwnVertex(s, v, isSource, at, color)) return;
    const uint32_t* ends = isSource ? v.source : v.target;
    const Vec3d lifted = turned(d.sphere.transpose(), dir);
    const Eigen::Vector2d x =
        rotate(Eigen::Vector2d(lifted.x() / lifted.z(), lifted.y() / lifted.z()), -d.turn);
    const uint32_t t = isSource ? v.sourceTriangle : v.targetTriangle;
    uint32_t corner[3];
    double w[3];
    if (t < s.triangles.size()) {
        for (int c = 0; c < 3; ++c) corner[c] = s.triangles[t][c];
        const Eigen::Vector2d p0 = d.uv[corner[0]], e1 = d.uv[corner[1]] - p0,
                              e2 = d.uv[corner[2]] - p0;
        const Eigen::Vector2d r = x - p0;
        const double det = e1.x() * e2.y() - e1.y() * e2.x();
        w[1] = (r.x() * e2.y() - r.y() * e2.x()) / det;
        w[2] = (e1.x() * r.y() - e1.y() * r.x()) / det;
        w[0] = 1.0 - w[1] - w[2];
        if (v.kind == OverlayVertex::Kind::Crossing) // on the edge (ends[0], ends[1])
            for (int c = 0; c < 3; ++c)
                if (corner[c] != ends[0] && corner[c] != ends[1]) {
                    const double rest = 1.0 - w[c];
                    w[c] = 0.0;
                    for (int o = 0; o < 3; ++o) w[o] /= o == c ? 1.0 : rest;
                }
    } else { // the cap over boundary edge k: where the ray from the centre meets the edge
        const size_t k = t - s.triangles.size(), n = d.boundary.size();
        corner[0] = d.boundary[k];
        corner[1] = d.boundary[(k + 1) % n];
        corner[2] = corner[0];
        const Eigen::Vector2d p = d.uv[corner[0]], e = d.uv[corner[1]] - p;
        // p + lambda e = mu x
        const double det = e.x() * x.y() - e.y() * x.x();
        const double lambda = std::abs(det) > 0.0 ? (p.y() * x.x() - p.x() * x.y()) / det : 0.0;
        w[1] = std::clamp(lambda, 0.0, 1.0);
        w[0] = 1.0 - w[1];
        w[2] = 0.0;
    }
    at = w[0] * s.points[corner[0]] + w[1] * s.points[corner[1]] + w[2] * s.points[corner[2]];
    if (color)
        *color = Vec3f(w[0] * s.color(corner[0]) + w[1] * s.color(corner[1]) +
                       w[2] * s.color(corner[2]));
}

/// The target's disk with each landmark's target point made a vertex and the disk warped
/// (DiskWarp) so that it lands where the source's landmark point is in the source's disk; the
/// target's disk turned by `turn` first. Throws UserError at the first landmark's pair when the
/// landmarks fold the map.
Disk warpedToLandmarks(const MergeSide& a, const Disk& da, MergeSide& b, double turn,
                       const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where)
{
    std::vector<Eigen::Vector2d> to, from;
    for (const MergeSide::Place& p : snapLandmarks(a, landmarks, true)) {
        const Vec3I& t = a.triangles[p.triangle];
        to.push_back(p.weights[0] * da.uv[t[0]] + p.weights[1] * da.uv[t[1]] +
                     p.weights[2] * da.uv[t[2]]);
    }
    snapLandmarks(b, landmarks, false); // the checks; each is placed once the last is in
    std::vector<uint32_t> held;
    for (const SurfaceLandmark& l : landmarks) held.push_back(b.insert(b.nearest(l.target)));
    const Mesh mesh = b.compacted();
    Disk d = diskOf(b, where);
    for (uint32_t v : held) from.push_back(rotate(d.uv[v], turn));
    const DiskWarp warp(from, to);
    for (Eigen::Vector2d& p : d.uv) p = warp(rotate(p, turn));
    if (const size_t folded = foldedTriangles(mesh, d.uv); folded > 0)
        throw UserError(landmarks.front().where,
                        "[[pair]]: the landmarks (" + landmarkPlaces(landmarks) + ") fold " +
                            std::to_string(folded) + " triangles of " + b.mesh->file.string() +
                            "'s disk map: they cannot meet without folding it");
    return d;
}

} // namespace

Corresponded diskMerge(const Mesh& source, const Mesh& target,
                       const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where)
{
    const MergeSide a(source);
    MergeSide b(target);
    const Disk da = diskOf(a, where);
    Disk db = diskOf(b, where);
    double fit = bestTurn(a, da, b, db);
    if (!landmarks.empty()) { // turned by the fit, then warped onto the landmarks
        db = warpedToLandmarks(a, da, b, fit, landmarks, where);
        fit = 0.0;
    }
    // The caps' poles apart (the regions in both caps are dropped, but must have areas).
    Vec3d poleB(1e-3, 2e-3, -1.0);
    poleB.normalize();
    const SphereTriangulation sa = lift(a, da, Vec3d(0.0, 0.0, -1.0));
    const uint32_t capA = uint32_t(a.triangles.size()), capB = uint32_t(b.triangles.size());
    Overlay merged;
    std::vector<Vec3I> kept;
    std::vector<std::pair<uint32_t, uint32_t>> keptRegions;
    db.turn = fit;
    for (int attempt = 0; attempt < kMergeAttempts; ++attempt) {
        db.sphere = mergeTurn(attempt);
        merged = overlay(sa, lift(b, db, poleB));
        // Keep the regions inside either disk.
        kept.clear();
        keptRegions.clear();
        for (size_t t = 0; t < merged.triangles.size(); ++t)
            if (merged.regions[t].first < capA || merged.regions[t].second < capB) {
                kept.push_back(merged.triangles[t]);
                keptRegions.push_back(merged.regions[t]);
            }
        if (invertedTriangles(merged.grid, kept) == 0) break;
    }
    if (const size_t folded = invertedTriangles(merged.grid, kept); folded > 0)
        throw UserError(where, "merging " + source.file.string() + " and " + target.file.string() +
                                   " in the plane left " + std::to_string(folded) +
                                   " triangles without area");
    // Renumbered without the poles and what only the caps hold.
    std::vector<int64_t> index(merged.vertices.size(), -1);
    for (const Vec3I& t : kept)
        for (int c = 0; c < 3; ++c) index[t[c]] = 0;
    std::vector<uint32_t> vertices;
    for (size_t v = 0; v < index.size(); ++v)
        if (index[v] == 0) {
            index[v] = int64_t(vertices.size());
            vertices.push_back(uint32_t(v));
        }
    Corresponded out;
    out.used = Correspondence::Disk;
    for (Vec3I& t : kept)
        t = Vec3I(uint32_t(index[t[0]]), uint32_t(index[t[1]]), uint32_t(index[t[2]]));
    out.triangles = std::move(kept);
    out.crossings = vertices.size() - a.points.size() - b.points.size();
    placeMergedVertices(out, vertices.size(), source.hasColors() || target.hasColors(),
                        [&](size_t i, bool isSource, Vec3d& at, Vec3f* color) {
                            const uint32_t v = vertices[i];
                            place(isSource ? a : b, isSource ? da : db, merged.vertices[v],
                                  isSource, merged.directions[v], at, color);
                        });
    placeMergedUVs(out, keptRegions, a, b);
    return out;
}

} // namespace volmorph::detail
