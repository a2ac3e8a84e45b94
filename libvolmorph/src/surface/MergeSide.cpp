#include "MergeSide.h"

#include <Eigen/Geometry>

#include <openvdb/math/Proximity.h>

#include <algorithm>
#include <limits>
#include <sstream>

namespace volmorph::detail {

MergeSide::MergeSide(const Mesh& m) : mesh(&m)
{
    std::vector<char> used(m.points.size(), 0);
    for (const Vec3I& t : m.triangles) used[t[0]] = used[t[1]] = used[t[2]] = 1;
    std::vector<uint32_t> local(m.points.size(), 0);
    for (uint32_t v = 0; v < m.points.size(); ++v)
        if (used[v]) {
            local[v] = uint32_t(points.size());
            points.emplace_back(m.points[v]);
            original.push_back(v);
        }
    for (const Vec3I& t : m.triangles)
        triangles.emplace_back(local[t[0]], local[t[1]], local[t[2]]);
    for (uint32_t v : original) colors.push_back(m.hasColors() ? Vec3d(m.colors[v]) : Vec3d(0.8));
    if (m.hasUVs())
        for (size_t j = 0; j < m.triangles.size(); ++j)
            uvs.push_back({Vec2d(m.uvs[3 * j]), Vec2d(m.uvs[3 * j + 1]), Vec2d(m.uvs[3 * j + 2])});
    const auto [lo, hi] = m.bounds();
    diagonal = std::max((hi - lo).length(), 1e-300);
}

MergeSide::Place MergeSide::nearest(const Vec3d& p) const
{
    Place best;
    best.distance = std::numeric_limits<double>::infinity();
    for (uint32_t j = 0; j < triangles.size(); ++j) {
        const Vec3I& t = triangles[j];
        Vec3d uvw;
        const Vec3d q = openvdb::math::closestPointOnTriangleToPoint(points[t[0]], points[t[1]],
                                                                     points[t[2]], p, uvw);
        if ((q - p).length() < best.distance) best = {j, uvw, q, (q - p).length()};
    }
    return best;
}

uint32_t MergeSide::insert(const Place& at)
{
    const Vec3I t = triangles[at.triangle];
    const Vec3d& w = at.weights;
    for (int c = 0; c < 3; ++c)
        if (w[c] > 1.0 - 1e-12) return t[c];
    const uint32_t m = uint32_t(points.size());
    points.push_back(w[0] * points[t[0]] + w[1] * points[t[1]] + w[2] * points[t[2]]);
    colors.push_back(w[0] * colors[t[0]] + w[1] * colors[t[1]] + w[2] * colors[t[2]]);
    original.push_back(kNone);
    int onEdge = -1; // the corner opposite the edge the point lies on
    for (int c = 0; c < 3; ++c)
        if (w[c] < 1e-12) onEdge = c;
    if (onEdge < 0) { // inside: three triangles about it
        triangles[at.triangle] = Vec3I(t[0], t[1], m);
        triangles.emplace_back(t[1], t[2], m);
        triangles.emplace_back(t[2], t[0], m);
        if (!uvs.empty()) {
            const std::array<Vec2d, 3> uv = uvs[at.triangle];
            const Vec2d um = w[0] * uv[0] + w[1] * uv[1] + w[2] * uv[2];
            uvs[at.triangle] = {uv[0], uv[1], um};
            uvs.push_back({uv[1], uv[2], um});
            uvs.push_back({uv[2], uv[0], um});
        }
        return m;
    }
    // On edge (u, v): each of its triangles (u, v, x) becomes (u, m, x) and (m, v, x).
    const uint32_t u = t[(onEdge + 1) % 3], v = t[(onEdge + 2) % 3];
    // The point is (1 - lambda) u + lambda v.
    const double lambda = w[(onEdge + 2) % 3] / (w[(onEdge + 1) % 3] + w[(onEdge + 2) % 3]);
    const size_t count = triangles.size();
    for (size_t j = 0; j < count; ++j)
        for (int c = 0; c < 3; ++c) {
            const Vec3I s = triangles[j];
            const uint32_t a = s[c], b = s[(c + 1) % 3], x = s[(c + 2) % 3];
            if (!((a == u && b == v) || (a == v && b == u))) continue;
            triangles[j] = Vec3I(a, m, x);
            triangles.emplace_back(m, b, x);
            if (!uvs.empty()) { // this triangle's own coordinates along the edge (a seam's differ)
                const std::array<Vec2d, 3> uv = uvs[j];
                const Vec2d& ua = uv[size_t(c)];
                const Vec2d& ub = uv[size_t((c + 1) % 3)];
                const Vec2d um =
                    a == u ? (1.0 - lambda) * ua + lambda * ub : lambda * ua + (1.0 - lambda) * ub;
                uvs[j] = {ua, um, uv[size_t((c + 2) % 3)]};
                uvs.push_back({um, ub, uv[size_t((c + 2) % 3)]});
            }
            break;
        }
    return m;
}

Vec2d MergeSide::uvAt(uint32_t triangle, const Vec3d& p) const
{
    if (uvs.empty()) return Vec2d(0.0);
    if (triangle >= triangles.size()) triangle = nearest(p).triangle;
    const Vec3I& t = triangles[triangle];
    Vec3d w;
    openvdb::math::closestPointOnTriangleToPoint(points[t[0]], points[t[1]], points[t[2]], p, w);
    const std::array<Vec2d, 3>& uv = uvs[triangle];
    return w[0] * uv[0] + w[1] * uv[1] + w[2] * uv[2];
}

void placeMergedUVs(Corresponded& out, const std::vector<std::pair<uint32_t, uint32_t>>& regions,
                    const MergeSide& a, const MergeSide& b)
{
    if (a.uvs.empty() && b.uvs.empty()) return;
    out.sourceUVs.resize(3 * out.triangles.size());
    out.targetUVs.resize(3 * out.triangles.size());
    tbb::parallel_for(size_t(0), out.triangles.size(), [&](size_t j) {
        for (size_t c = 0; c < 3; ++c) {
            const uint32_t v = out.triangles[j][c];
            out.sourceUVs[3 * j + c] = a.uvAt(regions[j].first, out.source[v]);
            out.targetUVs[3 * j + c] = b.uvAt(regions[j].second, out.target[v]);
        }
    });
}

Mesh MergeSide::compacted() const
{
    Mesh out;
    out.file = mesh->file;
    for (const Vec3d& p : points) out.points.emplace_back(Vec3f(p));
    if (mesh->hasColors())
        for (const Vec3d& c : colors) out.colors.emplace_back(Vec3f(c));
    out.triangles = triangles;
    for (const std::array<Vec2d, 3>& uv : uvs)
        for (const Vec2d& c : uv) out.uvs.emplace_back(Vec2f(c));
    out.report = mesh->report;
    analyzeTopology(out);
    return out;
}

Eigen::Matrix3d mergeTurn(int attempt)
{
    static const Eigen::Vector3d axes[3] = {
        {0.267, 0.535, 0.802}, {-0.711, 0.218, 0.669}, {0.498, -0.803, 0.327}};
    if (attempt == 0) return Eigen::Matrix3d::Identity();
    return Eigen::AngleAxisd(1e-6, axes[(attempt - 1) % 3].normalized()).toRotationMatrix();
}

Vec3d turned(const Eigen::Matrix3d& m, const Vec3d& v)
{
    const Eigen::Vector3d e = m * Eigen::Vector3d(v.x(), v.y(), v.z());
    return {e.x(), e.y(), e.z()};
}

std::string pointText(const Vec3d& p)
{
    std::ostringstream os;
    os.precision(6);
    os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
    return os.str();
}

} // namespace volmorph::detail
