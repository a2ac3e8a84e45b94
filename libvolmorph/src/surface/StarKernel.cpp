#include "StarKernel.h"

#include <Eigen/Dense>

#include <algorithm>
#include <limits>

namespace volmorph::detail {
namespace {

/// A triangle's plane as n . x + depth <= d (n the unit outward normal): x lies at least `depth`
/// inside it.
struct Plane {
    Eigen::Vector4d a; ///< (n, 1)
    double d = 0.0;
    uint32_t triangle = 0;
};

std::vector<Plane> planes(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles)
{
    std::vector<Plane> out;
    out.reserve(triangles.size());
    for (uint32_t j = 0; j < triangles.size(); ++j) {
        const Vec3I& t = triangles[j];
        const Vec3d n = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
        const double len = n.length();
        if (!(len > 0.0)) continue;
        const Vec3d u = n / len;
        out.push_back({Eigen::Vector4d(u.x(), u.y(), u.z(), 1.0), u.dot(points[t[0]]), j});
    }
    return out;
}

/// The component of `c` orthogonal to the rows of `rows` (empty rows: c itself).
Eigen::Vector4d project(const std::vector<Eigen::Vector4d>& rows, const Eigen::Vector4d& c)
{
    if (rows.empty()) return c;
    Eigen::Matrix<double, 4, Eigen::Dynamic> m(4, Eigen::Index(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) m.col(Eigen::Index(i)) = rows[i];
    const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 4, Eigen::Dynamic>> qr(m);
    const Eigen::Matrix4d q = qr.householderQ();
    Eigen::Vector4d d = c;
    for (Eigen::Index i = 0; i < qr.rank(); ++i) d -= q.col(i).dot(c) * q.col(i);
    return d;
}

/// The multipliers of the active rows in c = sum lambda_i a_i (least squares).
Eigen::VectorXd multipliers(const std::vector<Eigen::Vector4d>& rows, const Eigen::Vector4d& c)
{
    Eigen::Matrix<double, 4, Eigen::Dynamic> m(4, Eigen::Index(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) m.col(Eigen::Index(i)) = rows[i];
    return m.colPivHouseholderQr().solve(c);
}

} // namespace

KernelPoint kernelDepth(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                        const Vec3d& point)
{
    KernelPoint k{point, std::numeric_limits<double>::infinity(), 0};
    for (const Plane& p : planes(points, triangles)) {
        const double depth =
            p.d - p.a.head<3>().dot(Eigen::Vector3d(point.x(), point.y(), point.z()));
        if (depth < k.margin) {
            k.margin = depth;
            k.worstTriangle = p.triangle;
        }
    }
    return k;
}

KernelPoint deepestKernelPoint(const std::vector<Vec3d>& points,
                               const std::vector<Vec3I>& triangles)
{
    const std::vector<Plane> all = planes(points, triangles);
    Vec3d mean(0.0);
    for (const Vec3d& p : points) mean += p;
    mean /= double(std::max<size_t>(points.size(), 1));
    // Feasible start: the mean at the depth of its nearest plane (negative when outside one).
    Eigen::Vector4d y(mean.x(), mean.y(), mean.z(), 0.0);
    y(3) = kernelDepth(points, triangles, mean).margin;
    const Eigen::Vector4d objective(0.0, 0.0, 0.0, 1.0);
    std::vector<size_t> active;
    const size_t maxSteps = 64 + 4 * all.size();
    for (size_t step = 0; step < maxSteps && !all.empty(); ++step) {
        std::vector<Eigen::Vector4d> rows;
        for (size_t i : active) rows.push_back(all[i].a);
        Eigen::Vector4d dir = project(rows, objective);
        if (dir.norm() < 1e-12) { // no way up along the active planes: leave one, or stop
            const Eigen::VectorXd lambda = multipliers(rows, objective);
            Eigen::Index worst = 0;
            if (lambda.minCoeff(&worst) >= -1e-12) break; // optimal
            active.erase(active.begin() + worst);
            continue;
        }
        // Ratio test: the first plane the step meets.
        double alpha = std::numeric_limits<double>::infinity();
        size_t blocking = all.size();
        for (size_t i = 0; i < all.size(); ++i) {
            const double rate = all[i].a.dot(dir);
            if (rate <= 1e-12 * dir.norm()) continue;
            const double slack = std::max(0.0, all[i].d - all[i].a.dot(y));
            if (slack / rate < alpha) {
                alpha = slack / rate;
                blocking = i;
            }
        }
        if (blocking == all.size()) break; // unbounded: not a closed mesh
        y += alpha * dir;
        active.push_back(blocking);
    }
    return kernelDepth(points, triangles, Vec3d(y(0), y(1), y(2)));
}

} // namespace volmorph::detail
