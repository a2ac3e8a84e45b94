#include "WindingNumber.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

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

size_t repairOrientation(Mesh& mesh)
{
    const size_t n = mesh.triangles.size();
    // Directed edge (a -> b) to the triangles that use it, to find each triangle's neighbours.
    std::unordered_map<uint64_t, std::vector<uint32_t>> byEdge;
    byEdge.reserve(3 * n);
    auto key = [](uint32_t a, uint32_t b) {
        return (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    };
    for (uint32_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k)
            byEdge[key(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3])].push_back(t);

    auto traverses = [&mesh](uint32_t t, uint32_t a, uint32_t b) {
        const Vec3I& tri = mesh.triangles[t];
        for (int k = 0; k < 3; ++k)
            if (tri[k] == a && tri[(k + 1) % 3] == b) return true;
        return false;
    };

    // Breadth-first over manifold edges; flipRelative[t] says t must flip to agree with its seed.
    std::vector<int> shell(n, -1);
    std::vector<char> flipRelative(n, 0);
    std::vector<std::vector<uint32_t>> shells;
    for (uint32_t seed = 0; seed < n; ++seed) {
        if (shell[seed] >= 0) continue;
        const int id = int(shells.size());
        shells.emplace_back();
        std::vector<uint32_t> queue{seed};
        shell[seed] = id;
        for (size_t q = 0; q < queue.size(); ++q) {
            const uint32_t t = queue[q];
            shells[id].push_back(t);
            const Vec3I& tri = mesh.triangles[t];
            for (int k = 0; k < 3; ++k) {
                // Orientation of t's edge as t will be after its relative flip.
                uint32_t a = tri[k], b = tri[(k + 1) % 3];
                if (flipRelative[t]) std::swap(a, b);
                const auto& users = byEdge[key(a, b)];
                if (users.size() != 2) continue; // boundary or non-manifold: no orientation to copy
                const uint32_t u = users[0] == t ? users[1] : users[0];
                if (shell[u] >= 0) continue;
                shell[u] = id;
                // Consistent neighbours traverse the shared edge the other way (b -> a).
                flipRelative[u] = traverses(u, a, b) ? 1 : 0;
                queue.push_back(u);
            }
        }
    }

    size_t flipped = 0;
    auto flip = [&mesh, &flipped](uint32_t t) {
        std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
        ++flipped;
    };
    // The majority orientation of each shell wins.
    for (const auto& triangles : shells) {
        size_t relative = 0;
        for (uint32_t t : triangles) relative += flipRelative[t];
        const bool flipMarked = relative * 2 <= triangles.size();
        for (uint32_t t : triangles)
            if (bool(flipRelative[t]) == flipMarked) flip(t);
    }
    // Inverted shells: negative volume and inside no other shell.
    std::vector<double> volume(shells.size(), 0.0);
    for (size_t s = 0; s < shells.size(); ++s)
        for (uint32_t t : shells[s]) {
            const Vec3I& tri = mesh.triangles[t];
            volume[s] += Vec3d(mesh.points[tri[0]])
                             .dot(Vec3d(mesh.points[tri[1]]).cross(Vec3d(mesh.points[tri[2]]))) /
                         6.0;
        }
    // Nesting is checked pairwise; beyond this many shells (debris, particles) it is skipped and
    // every negative shell is turned outward.
    constexpr size_t kMaxNestingShells = 64;
    std::vector<WindingNumber> perShell;
    if (shells.size() <= kMaxNestingShells) {
        perShell.reserve(shells.size());
        for (const auto& triangles : shells) {
            std::vector<Vec3I> tris;
            for (uint32_t t : triangles) tris.push_back(mesh.triangles[t]);
            perShell.emplace_back(mesh.points, std::move(tris));
        }
    }
    for (size_t s = 0; s < shells.size(); ++s) {
        if (volume[s] >= 0.0) continue;
        bool nested = false;
        if (!perShell.empty()) {
            const Vec3d probe(mesh.points[mesh.triangles[shells[s][0]][0]]);
            for (size_t o = 0; o < shells.size() && !nested; ++o)
                nested = o != s && std::abs(perShell[o](probe)) > 0.5;
        }
        if (!nested)
            for (uint32_t t : shells[s]) flip(t);
    }
    analyzeTopology(mesh);
    return flipped;
}

} // namespace volmorph::detail
