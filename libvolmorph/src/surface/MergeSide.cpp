#include "MergeSide.h"

#include <Eigen/Geometry>

#include <algorithm>
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
    const auto [lo, hi] = m.bounds();
    diagonal = std::max((hi - lo).length(), 1e-300);
}

Mesh MergeSide::compacted() const
{
    Mesh out;
    out.file = mesh->file;
    for (uint32_t i : original) out.points.push_back(mesh->points[i]);
    if (mesh->hasColors())
        for (uint32_t i : original) out.colors.push_back(mesh->colors[i]);
    out.triangles = triangles;
    out.report = mesh->report;
    analyzeTopology(out);
    return out;
}

Eigen::Matrix3d mergeTurn(int attempt)
{
    static const Eigen::Vector3d axes[3] = {
        {0.267, 0.535, 0.802}, {-0.711, 0.218, 0.669}, {0.498, -0.803, 0.327}};
    return Eigen::AngleAxisd(1e-6, axes[attempt % 3].normalized()).toRotationMatrix();
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
