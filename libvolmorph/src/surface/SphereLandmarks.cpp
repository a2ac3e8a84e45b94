#include "SphereLandmarks.h"

#include "Landmarks.h"
#include "SphereStretch.h"

#include <cmath>

namespace volmorph::detail {
namespace {

/// The pull's steps, and the extra steps a landmark held back by its triangles may take.
constexpr int kSteps = 24;
constexpr int kExtraSteps = 24;

std::vector<Fan> fans(size_t vertices, const std::vector<Vec3I>& triangles)
{
    std::vector<Fan> out(vertices);
    for (const Vec3I& t : triangles) {
        out[t[0]].emplace_back(t[1], t[2]);
        out[t[1]].emplace_back(t[2], t[0]);
        out[t[2]].emplace_back(t[0], t[1]);
    }
    return out;
}

/// The point `share` of the way from `a` to `b` along their great circle (unit vectors).
Vec3d along(const Vec3d& a, const Vec3d& b, double share)
{
    const double angle = std::atan2(a.cross(b).length(), a.dot(b));
    if (share >= 1.0 || angle < 1e-15) return share >= 1.0 ? b : a;
    const double s = std::sin(angle);
    return (std::sin((1.0 - share) * angle) / s) * a + (std::sin(share * angle) / s) * b;
}

/// Moves landmark `v` `share` of the way to `goal`, or as far as its triangles allow (bisection).
void advance(const StretchMesh& m, uint32_t v, const Vec3d& goal, double share, const Fan& fan)
{
    Vec3d& at = (*m.directions)[v];
    const Vec3d from = at;
    if (fanValid(m, v, along(from, goal, share), fan)) {
        at = along(from, goal, share);
        return;
    }
    double lo = 0.0, hi = share;
    for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        (fanValid(m, v, along(from, goal, mid), fan) ? lo : hi) = mid;
    }
    at = along(from, goal, lo);
}

} // namespace

std::optional<std::array<size_t, 3>> mirroredLandmarks(const std::vector<Vec3d>& from,
                                                       const std::vector<Vec3d>& goals)
{
    const auto det = [](const std::vector<Vec3d>& p, size_t i, size_t j, size_t k) {
        return p[i].dot(p[j].cross(p[k]));
    };
    // Two maps of one shape can differ enough to turn a few triples round (a long thin shape's
    // do); a mirrored placement turns every one.
    std::optional<std::array<size_t, 3>> first;
    const size_t n = from.size();
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j)
            for (size_t k = j + 1; k < n; ++k) {
                const double a = det(from, i, j, k), b = det(goals, i, j, k);
                if (std::abs(a) <= kClearTriple || std::abs(b) <= kClearTriple) continue;
                if (a * b > 0.0) return std::nullopt;
                if (!first) first = std::array<size_t, 3>{i, j, k};
            }
    return first;
}

bool pullToLandmarks(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                     std::vector<Vec3d>& directions, const std::vector<uint32_t>& vertices,
                     const std::vector<Vec3d>& goals, Interrupter* interrupter)
{
    if (vertices.empty()) return true;
    std::vector<Vec3d> from;
    for (uint32_t v : vertices) from.push_back(directions[v]);
    const Eigen::Matrix3d turn = landmarkTurn(from, goals);
    for (Vec3d& d : directions) {
        const Eigen::Vector3d t = turn * Eigen::Vector3d(d.x(), d.y(), d.z());
        d = Vec3d(t.x(), t.y(), t.z());
    }
    const std::vector<Fan> fan = fans(points.size(), triangles);
    std::vector<char> pinned(points.size(), 0);
    for (uint32_t v : vertices) pinned[v] = 1;
    const StretchMesh m{&points, &directions, StretchMesh::evenStretch(points, triangles)};
    for (int step = 0; step < kSteps + kExtraSteps; ++step) {
        throwIfInterrupted(interrupter);
        const double share = step < kSteps ? 1.0 / double(kSteps - step) : 1.0;
        bool arrived = true;
        for (size_t i = 0; i < vertices.size(); ++i) {
            advance(m, vertices[i], goals[i], share, fan[vertices[i]]);
            arrived = arrived && directions[vertices[i]] == goals[i];
        }
        if (arrived && step >= kSteps - 1) return true;
        for (uint32_t v = 0; v < points.size(); ++v)
            if (!pinned[v]) relaxVertex(m, v, fan[v], 1);
    }
    return false;
}

} // namespace volmorph::detail
