#include "mesh/HoleFill.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <tuple>
#include <utility>
#include <vector>

namespace volmorph::detail {
namespace {

using Loop = std::vector<uint32_t>;

/// A loop's patch is a disc of concentric rings, each 6 vertices shorter than the one outside it
/// (as the rings of a hexagonal grid), at most this many vertices on its first inner ring: a hole
/// of any size becomes a system of at most about 400^2 / 12 = 13k unknowns.
constexpr int kMaxRing = 400;

uint64_t edgeKey(uint32_t a, uint32_t b)
{
    return (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
}

/// The part of `loop` from place k (a vertex the walk has come back to) on is a closed loop: moved
/// to `loops` (or counted as unclosed when shorter than 3), leaving `loop` ending at that vertex.
void splitOff(Loop& loop, std::unordered_map<uint32_t, size_t>& at, size_t k,
              std::vector<Loop>& loops, size_t& unclosed)
{
    Loop part(loop.begin() + std::ptrdiff_t(k), loop.end());
    for (size_t i = k + 1; i < loop.size(); ++i) at.erase(loop[i]);
    loop.resize(k + 1);
    if (part.size() >= 3)
        loops.push_back(std::move(part));
    else
        ++unclosed;
}

/// The holes' loops. A triangle's boundary edge a -> b is walked b -> a, so each loop runs the way
/// a patch triangle on it must traverse it to agree with the mesh's orientation.
std::vector<Loop> boundaryLoops(const Mesh& mesh, size_t& unclosed)
{
    std::unordered_map<uint64_t, uint32_t> uses;
    uses.reserve(3 * mesh.triangles.size());
    for (const Vec3I& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) ++uses[edgeKey(t[k], t[(k + 1) % 3])];
    std::unordered_map<uint32_t, std::vector<uint32_t>> next; // loop edges leaving a vertex
    std::vector<uint32_t> starts;
    size_t edges = 0;
    for (const Vec3I& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = t[k], b = t[(k + 1) % 3];
            if (uses[edgeKey(a, b)] != 1) continue;
            next[b].push_back(a);
            starts.push_back(b);
            ++edges;
        }
    std::vector<Loop> loops;
    for (const uint32_t start : starts) {
        std::vector<uint32_t>& first = next[start];
        if (first.empty()) continue;
        Loop loop{start};
        std::unordered_map<uint32_t, size_t> at{{start, 0}}; // each vertex's place in `loop`
        uint32_t v = first.back();
        first.pop_back();
        while (v != start && loop.size() <= edges) {
            if (auto seen = at.find(v); seen != at.end()) {
                // A pinch: the walk came back to v, closing a loop of its own. Each is patched
                // apart (one patch across both would reuse the pinch's edges).
                splitOff(loop, at, seen->second, loops, unclosed);
            } else {
                at[v] = loop.size();
                loop.push_back(v);
            }
            std::vector<uint32_t>& out = next[v];
            if (out.empty()) break;
            v = out.back();
            out.pop_back();
        }
        if (v == start && loop.size() >= 3)
            loops.push_back(std::move(loop));
        else
            ++unclosed;
    }
    return loops;
}

/// A patch in local numbering: 0 .. rim.size()-1 are the loop's vertices, the rest are new.
struct Patch {
    Loop rim;
    uint32_t added = 0;
    std::vector<Vec3I> triangles;
};

/// Triangulates the band between two cyclic rings by their parameters in [0, 1) (`ua`, `ub`, each
/// with 1 appended), advancing along whichever ring's next vertex comes first. Orientation: the
/// outer ring runs with the loop, so the quad a_i a_i+1 b_j+1 b_j is counter-clockwise.
void zip(const std::vector<uint32_t>& a, const std::vector<double>& ua,
         const std::vector<uint32_t>& b, const std::vector<double>& ub, std::vector<Vec3I>& out)
{
    const size_t na = a.size(), nb = b.size();
    size_t i = 0, j = 0;
    while (i < na || (j < nb && nb > 1)) {
        const bool alongA = nb == 1 || j >= nb || (i < na && ua[i + 1] <= ub[j + 1]);
        if (alongA) {
            out.emplace_back(a[i], a[(i + 1) % na], b[j % nb]);
            ++i;
        } else {
            out.emplace_back(a[i % na], b[(j + 1) % nb], b[j]);
            ++j;
        }
    }
}

/// The loop's disc: rings of target - 6, target - 12, ... vertices inside it, then one centre
/// vertex, where target is the loop's perimeter over the spacing (at most kMaxRing).
Patch ringPatch(const Loop& loop, const Mesh& mesh, double spacing)
{
    Patch patch;
    patch.rim = loop;
    const size_t n = loop.size();
    std::vector<double> u(n + 1, 0.0); // arc length along the loop, as a fraction
    for (size_t i = 0; i < n; ++i)
        u[i + 1] =
            u[i] + (Vec3d(mesh.points[loop[(i + 1) % n]]) - Vec3d(mesh.points[loop[i]])).length();
    const double perimeter = u[n];
    for (double& x : u) x /= perimeter;
    if (n == 3) {
        patch.triangles.emplace_back(0, 1, 2);
        return patch;
    }
    const double h = std::max(spacing, perimeter / double(n));
    int count = std::min(int(n), std::clamp(int(std::lround(perimeter / h)), 3, kMaxRing));
    std::vector<uint32_t> outer(n);
    for (uint32_t i = 0; i < n; ++i) outer[i] = i;
    std::vector<double> outerU = u;
    uint32_t nextId = uint32_t(n);
    for (;;) {
        count -= 6;
        const int size = count >= 3 ? count : 1; // the last ring is the centre
        std::vector<uint32_t> inner(static_cast<size_t>(size));
        std::vector<double> innerU(static_cast<size_t>(size) + 1);
        for (int j = 0; j < size; ++j) {
            inner[size_t(j)] = nextId++;
            innerU[size_t(j)] = double(j) / size;
        }
        innerU[size_t(size)] = 1.0;
        zip(outer, outerU, inner, innerU, patch.triangles);
        if (size == 1) break;
        outer = std::move(inner);
        outerU = std::move(innerU);
    }
    patch.added = nextId - uint32_t(n);
    return patch;
}

/// A neighbour in the fairing: a fixed mesh vertex (its mesh index) or an unknown (its index among
/// the patch's new vertices).
struct Neighbour {
    bool unknown;
    uint32_t id;
    bool operator<(const Neighbour& o) const
    {
        return std::tie(unknown, id) < std::tie(o.unknown, o.id);
    }
    bool operator==(const Neighbour& o) const { return unknown == o.unknown && id == o.id; }
};

/// Per vertex of the patch (local numbering), its neighbours: across the patch's triangles, and
/// for a rim vertex also across the mesh's (`meshRing`).
std::vector<std::vector<Neighbour>>
patchNeighbours(const Patch& patch,
                const std::unordered_map<uint32_t, std::vector<uint32_t>>& meshRing)
{
    const uint32_t n = uint32_t(patch.rim.size());
    auto neighbour = [&](uint32_t local) {
        return local < n ? Neighbour{false, patch.rim[local]} : Neighbour{true, local - n};
    };
    std::vector<std::vector<Neighbour>> out(n + patch.added);
    for (const Vec3I& t : patch.triangles)
        for (int k = 0; k < 3; ++k)
            for (int e = 1; e < 3; ++e) out[t[k]].push_back(neighbour(t[(k + e) % 3]));
    for (uint32_t i = 0; i < n; ++i) {
        const auto ring = meshRing.find(patch.rim[i]);
        if (ring != meshRing.end())
            for (const uint32_t w : ring->second) out[i].push_back(Neighbour{false, w});
    }
    for (auto& list : out) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
    }
    return out;
}

/// The values (position, then colour when the mesh has them) of the patch's new vertices that
/// minimize the sum of squared umbrella Laplacians over every patch vertex, rim included.
Eigen::MatrixXd fair(const Patch& patch, const Mesh& mesh,
                     const std::unordered_map<uint32_t, std::vector<uint32_t>>& meshRing)
{
    const uint32_t n = uint32_t(patch.rim.size());
    const int columns = mesh.hasColors() ? 6 : 3;
    auto fixedValue = [&](uint32_t v, int c) {
        return c < 3 ? double(mesh.points[v][c]) : double(mesh.colors[v][c - 3]);
    };
    const std::vector<std::vector<Neighbour>> neighbours = patchNeighbours(patch, meshRing);
    const Eigen::Index rows = Eigen::Index(neighbours.size());
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixXd fixed = Eigen::MatrixXd::Zero(rows, columns);
    for (Eigen::Index r = 0; r < rows; ++r) {
        const auto& list = neighbours[size_t(r)];
        if (list.empty()) continue;
        const double w = 1.0 / double(list.size());
        for (const Neighbour& nb : list) {
            if (nb.unknown)
                entries.emplace_back(r, Eigen::Index(nb.id), w);
            else
                for (int c = 0; c < columns; ++c) fixed(r, c) += w * fixedValue(nb.id, c);
        }
        if (r >= n)
            entries.emplace_back(r, r - n, -1.0);
        else
            for (int c = 0; c < columns; ++c) fixed(r, c) -= fixedValue(patch.rim[size_t(r)], c);
    }
    Eigen::SparseMatrix<double> laplacian(rows, patch.added);
    laplacian.setFromTriplets(entries.begin(), entries.end());
    const Eigen::SparseMatrix<double> normal = laplacian.transpose() * laplacian;
    const Eigen::MatrixXd rhs = -(laplacian.transpose() * fixed);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() == Eigen::Success) {
        Eigen::MatrixXd x = solver.solve(rhs);
        if (solver.info() == Eigen::Success && x.allFinite()) return x;
    }
    // Not expected (the system is positive definite); the rim's centroid keeps the patch closed.
    Eigen::MatrixXd centre = Eigen::MatrixXd::Zero(patch.added, columns);
    for (const uint32_t v : patch.rim)
        for (int c = 0; c < columns; ++c) centre.col(c).array() += fixedValue(v, c) / n;
    return centre;
}

/// Each rim vertex's neighbours across the mesh's triangles.
std::unordered_map<uint32_t, std::vector<uint32_t>> rimRings(const Mesh& mesh,
                                                             const std::vector<Loop>& loops)
{
    std::unordered_map<uint32_t, std::vector<uint32_t>> ring;
    for (const Loop& loop : loops)
        for (const uint32_t v : loop) ring[v];
    for (const Vec3I& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            auto it = ring.find(t[k]);
            if (it == ring.end()) continue;
            it->second.push_back(t[(k + 1) % 3]);
            it->second.push_back(t[(k + 2) % 3]);
        }
    return ring;
}

} // namespace

HoleFillStats fillHoles(Mesh& mesh, double spacing)
{
    HoleFillStats stats;
    const std::vector<Loop> loops = boundaryLoops(mesh, stats.unclosed);
    if (loops.empty()) return stats;
    const auto meshRing = rimRings(mesh, loops);
    for (const Loop& loop : loops) {
        const Patch patch = ringPatch(loop, mesh, spacing);
        const Eigen::MatrixXd values =
            patch.added ? fair(patch, mesh, meshRing) : Eigen::MatrixXd();
        const uint32_t base = uint32_t(mesh.points.size());
        for (uint32_t i = 0; i < patch.added; ++i) {
            mesh.points.emplace_back(float(values(i, 0)), float(values(i, 1)), float(values(i, 2)));
            if (mesh.hasColors())
                mesh.colors.emplace_back(float(values(i, 3)), float(values(i, 4)),
                                         float(values(i, 5)));
        }
        const uint32_t n = uint32_t(loop.size());
        for (const Vec3I& t : patch.triangles) {
            Vec3I global;
            for (int k = 0; k < 3; ++k) global[k] = t[k] < n ? loop[t[k]] : base + (t[k] - n);
            mesh.triangles.push_back(global);
        }
        stats.patchTriangles += patch.triangles.size();
        ++stats.holes;
    }
    if (stats.patchTriangles > 0) mesh.uvs.clear(); // the patches have no texture coordinates
    analyzeTopology(mesh);
    return stats;
}

} // namespace volmorph::detail
