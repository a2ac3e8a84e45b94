#include "DiskMap.h"

#include "Cotangent.h"
#include "mesh/DisjointSets.h"

#include <Eigen/Geometry>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace volmorph::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d at(const Mesh& mesh, uint32_t v)
{
    const Vec3f& p = mesh.points[v];
    return {double(p.x()), double(p.y()), double(p.z())};
}

uint64_t key(uint32_t a, uint32_t b)
{
    return (uint64_t(a) << 32) | b;
}

size_t pieces(const Mesh& mesh)
{
    DisjointSets sets(mesh.points.size());
    std::vector<bool> used(mesh.points.size(), false);
    for (const Vec3I& t : mesh.triangles) {
        sets.unite(t[0], t[1]);
        sets.unite(t[1], t[2]);
        used[t[0]] = used[t[1]] = used[t[2]] = true;
    }
    std::unordered_set<uint32_t> roots;
    for (uint32_t v = 0; v < mesh.points.size(); ++v)
        if (used[v]) roots.insert(sets.find(v));
    return roots.size();
}

/// Directed weights (row vertex, column vertex, weight) of the map's linear system: cotangent
/// weights (symmetric) or Floater's mean value weights (tan(angle / 2) / length, per corner).
struct Weight {
    uint32_t i, j;
    double w;
};

std::vector<Weight> weights(const Mesh& mesh, bool meanValue)
{
    std::vector<Weight> out;
    out.reserve(mesh.triangles.size() * 6);
    if (!meanValue) { // each corner weighs the edge opposite it, both ways
        forEachCotangentWeight(mesh.points, mesh.triangles,
                               [&](uint32_t, uint32_t a, uint32_t b, double w) {
                                   out.push_back({a, b, w});
                                   out.push_back({b, a, w});
                               });
        return out;
    }
    for (const Vec3I& t : mesh.triangles)
        for (int c = 0; c < 3; ++c) {
            const uint32_t i = t[c], j = t[(c + 1) % 3], k = t[(c + 2) % 3];
            const Eigen::Vector3d ej = at(mesh, j) - at(mesh, i), ek = at(mesh, k) - at(mesh, i);
            const double sine = ej.cross(ek).norm(), cosine = ej.dot(ek);
            if (!(sine > 1e-300)) continue;
            const double half = std::tan(0.5 * std::atan2(sine, cosine));
            out.push_back({i, j, half / ej.norm()});
            out.push_back({i, k, half / ek.norm()});
        }
    return out;
}

/// The interior vertices where the weighted springs balance, the boundary fixed at `uv`.
void solveInterior(const Mesh& mesh, const std::vector<bool>& fixed,
                   const std::vector<Weight>& springs, std::vector<Eigen::Vector2d>& uv)
{
    std::vector<int> row(mesh.points.size(), -1);
    int rows = 0;
    for (size_t v = 0; v < row.size(); ++v)
        if (!fixed[v]) row[v] = rows++;
    if (rows == 0) return;
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(rows, 2);
    for (const Weight& s : springs) {
        if (row[s.i] < 0) continue;
        entries.emplace_back(row[s.i], row[s.i], s.w);
        if (row[s.j] >= 0)
            entries.emplace_back(row[s.i], row[s.j], -s.w);
        else
            rhs.row(row[s.i]) += s.w * uv[s.j].transpose();
    }
    Eigen::SparseMatrix<double> a(rows, rows);
    a.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(a);
    const Eigen::MatrixXd x = lu.solve(rhs);
    for (size_t v = 0; v < row.size(); ++v)
        if (row[v] >= 0) uv[v] = x.row(row[v]).transpose();
}

} // namespace

std::vector<std::vector<uint32_t>> boundaryLoops(const Mesh& mesh, const SourceLocation& where)
{
    std::unordered_set<uint64_t> halfEdges;
    for (const Vec3I& t : mesh.triangles)
        for (int c = 0; c < 3; ++c) halfEdges.insert(key(t[c], t[(c + 1) % 3]));
    std::unordered_map<uint32_t, uint32_t> next;
    for (const Vec3I& t : mesh.triangles)
        for (int c = 0; c < 3; ++c) {
            const uint32_t a = t[c], b = t[(c + 1) % 3];
            if (halfEdges.count(key(b, a))) continue;
            if (!next.emplace(a, b).second)
                throw UserError(where, mesh.file.string() +
                                           ": the boundary touches itself at vertex " +
                                           std::to_string(a) + " (two boundary edges leave it)");
        }
    std::vector<std::vector<uint32_t>> loops;
    std::unordered_set<uint32_t> seen;
    for (const auto& [start, unused] : next) {
        if (seen.count(start)) continue;
        std::vector<uint32_t> loop;
        for (uint32_t v = start; seen.insert(v).second;) {
            loop.push_back(v);
            const auto n = next.find(v);
            if (n == next.end())
                throw UserError(where, mesh.file.string() + ": a boundary that does not close");
            v = n->second;
        }
        // Each loop from its smallest vertex, the loops by it: the same map whatever the hash
        // order.
        std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
        loops.push_back(std::move(loop));
    }
    std::sort(loops.begin(), loops.end());
    return loops;
}

size_t foldedTriangles(const Mesh& mesh, const std::vector<Eigen::Vector2d>& uv)
{
    size_t folded = 0;
    for (const Vec3I& t : mesh.triangles) {
        const Eigen::Vector2d e1 = uv[t[1]] - uv[t[0]], e2 = uv[t[2]] - uv[t[0]];
        if (!(e1.x() * e2.y() - e1.y() * e2.x() > 0.0)) ++folded;
    }
    return folded;
}

DiskMap harmonicDiskMap(const Mesh& mesh, const SourceLocation& where)
{
    if (const size_t n = pieces(mesh); n != 1)
        throw UserError(where, mesh.file.string() + ": " + std::to_string(n) +
                                   " pieces; a disk map needs one piece with one boundary loop");
    const std::vector<std::vector<uint32_t>> loops = boundaryLoops(mesh, where);
    if (loops.size() != 1)
        throw UserError(where,
                        mesh.file.string() + ": " +
                            (loops.empty() ? std::string("no boundary (a closed mesh)")
                                           : std::to_string(loops.size()) + " boundary loops") +
                            "; a disk map needs exactly one boundary loop");
    DiskMap map;
    map.boundary = loops[0];
    const std::vector<uint32_t>& b = map.boundary;
    // The loop on the unit circle, each vertex at its arc length's share of the loop's.
    std::vector<double> along(b.size() + 1, 0.0);
    for (size_t k = 0; k < b.size(); ++k)
        along[k + 1] = along[k] + (at(mesh, b[(k + 1) % b.size()]) - at(mesh, b[k])).norm();
    map.uv.assign(mesh.points.size(), Eigen::Vector2d::Zero());
    std::vector<bool> fixed(mesh.points.size(), false);
    for (size_t k = 0; k < b.size(); ++k) {
        const double angle = 2.0 * kPi * along[k] / along.back();
        map.uv[b[k]] = {std::cos(angle), std::sin(angle)};
        fixed[b[k]] = true;
    }
    for (bool meanValue : {false, true}) {
        std::vector<Eigen::Vector2d> uv = map.uv;
        solveInterior(mesh, fixed, weights(mesh, meanValue), uv);
        // Counter-clockwise as the triangles face: the loop may run either way round.
        double area = 0.0;
        for (const Vec3I& t : mesh.triangles) {
            const Eigen::Vector2d e1 = uv[t[1]] - uv[t[0]], e2 = uv[t[2]] - uv[t[0]];
            area += e1.x() * e2.y() - e1.y() * e2.x();
        }
        if (area < 0.0)
            for (Eigen::Vector2d& p : uv) p.y() = -p.y();
        if (meanValue || foldedTriangles(mesh, uv) == 0) {
            map.uv = std::move(uv);
            map.meanValue = meanValue;
            break;
        }
    }
    return map;
}

} // namespace volmorph::detail
