#include "mesh/WindingNumber.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace volmorph::detail {
namespace {

constexpr double kFourPi = 4.0 * 3.14159265358979323846;
constexpr uint32_t kLeafSize = 8;
/// A cluster is far when the query is more than kBeta of its radii from its centre; the dipole
/// term's relative error then falls like (1 / kBeta)^2 (Barill et al. use 2).
constexpr double kBeta = 2.0;

Vec3d corner(const std::vector<Vec3f>& points, uint32_t i)
{
    return Vec3d(points[i]);
}

} // namespace

WindingNumber::WindingNumber(const std::vector<Vec3f>& points, std::vector<Vec3I> triangles)
    : mPoints(&points), mTriangles(std::move(triangles))
{
    if (!mTriangles.empty()) {
        mNodes.reserve(2 * mTriangles.size() / kLeafSize + 2);
        build(0, uint32_t(mTriangles.size()));
    }
}

uint32_t WindingNumber::build(uint32_t first, uint32_t count)
{
    const uint32_t index = uint32_t(mNodes.size());
    mNodes.emplace_back();
    Node node;
    node.first = first;
    node.count = count;
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    Vec3d weighted(0.0);
    double area = 0.0;
    for (uint32_t i = first; i < first + count; ++i) {
        const Vec3I& t = mTriangles[i];
        const Vec3d a = corner(*mPoints, t[0]), b = corner(*mPoints, t[1]),
                    c = corner(*mPoints, t[2]);
        const Vec3d n = 0.5 * (b - a).cross(c - a);
        const double A = n.length();
        node.areaNormal += n;
        weighted += A * (a + b + c) / 3.0;
        area += A;
        const Vec3d centroid = (a + b + c) / 3.0;
        lo = minComponent(lo, centroid);
        hi = maxComponent(hi, centroid);
    }
    node.center = area > 0.0 ? weighted / area : 0.5 * (lo + hi);
    for (uint32_t i = first; i < first + count; ++i)
        for (int k = 0; k < 3; ++k)
            node.radius =
                std::max(node.radius, (corner(*mPoints, mTriangles[i][k]) - node.center).length());

    if (count > kLeafSize) {
        // Median split of the triangle centroids along the longest axis of their bounds.
        const Vec3d extent = hi - lo;
        const int axis = extent[0] > extent[1] ? (extent[0] > extent[2] ? 0 : 2)
                                               : (extent[1] > extent[2] ? 1 : 2);
        auto key = [this, axis](const Vec3I& t) {
            return double((*mPoints)[t[0]][axis]) + (*mPoints)[t[1]][axis] + (*mPoints)[t[2]][axis];
        };
        const uint32_t half = count / 2;
        std::nth_element(mTriangles.begin() + first, mTriangles.begin() + first + half,
                         mTriangles.begin() + first + count,
                         [&key](const Vec3I& x, const Vec3I& y) { return key(x) < key(y); });
        node.count = 0;
        node.left = build(first, half);
        node.right = build(first + half, count - half);
    }
    mNodes[index] = node;
    return index;
}

double WindingNumber::solidAngle(const Vec3I& tri, const Vec3d& p) const
{
    // Van Oosterom and Strackee (1983): tan(omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| + ...).
    const Vec3d a = corner(*mPoints, tri[0]) - p, b = corner(*mPoints, tri[1]) - p,
                c = corner(*mPoints, tri[2]) - p;
    const double la = a.length(), lb = b.length(), lc = c.length();
    const double det = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    return 2.0 * std::atan2(det, den);
}

double WindingNumber::operator()(const Vec3d& p) const
{
    if (mNodes.empty()) return 0.0;
    double sum = 0.0;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = mNodes[stack[--top]];
        const Vec3d r = n.center - p;
        const double d = r.length();
        if (d > kBeta * n.radius) {
            sum += n.areaNormal.dot(r) / (d * d * d); // dipole: the cluster as one oriented area
        } else if (n.count > 0) {
            for (uint32_t i = n.first; i < n.first + n.count; ++i)
                sum += solidAngle(mTriangles[i], p);
        } else {
            stack[top++] = n.left;
            stack[top++] = n.right;
        }
    }
    return sum / kFourPi;
}

double WindingNumber::exact(const Vec3d& p) const
{
    double sum = 0.0;
    for (const Vec3I& t : mTriangles) sum += solidAngle(t, p);
    return sum / kFourPi;
}

} // namespace volmorph::detail
