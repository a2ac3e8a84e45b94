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
        return m;
    }
    // On edge (u, v): each of its triangles (u, v, x) becomes (u, m, x) and (m, v, x).
    const uint32_t u = t[(onEdge + 1) % 3], v = t[(onEdge + 2) % 3];
    const size_t count = triangles.size();
    for (size_t j = 0; j < count; ++j)
        for (int c = 0; c < 3; ++c) {
            const Vec3I s = triangles[j];
            const uint32_t a = s[c], b = s[(c + 1) % 3], x = s[(c + 2) % 3];
            if (!((a == u && b == v) || (a == v && b == u))) continue;
            triangles[j] = Vec3I(a, m, x);
            triangles.emplace_back(m, b, x);
            break;
        }
    return m;
}

Mesh MergeSide::compacted() const
{
    Mesh out;
    out.file = mesh->file;
    for (const Vec3d& p : points) out.points.emplace_back(Vec3f(p));
    if (mesh->hasColors())
        for (const Vec3d& c : colors) out.colors.emplace_back(Vec3f(c));
    out.triangles = triangles;
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
