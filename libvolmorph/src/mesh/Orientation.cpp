#include "mesh/Orientation.h"

#include "mesh/WindingNumber.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>
#include <vector>

namespace volmorph::detail {
namespace {

/// The shells (connected across manifold edges) and, per triangle, whether it must flip to agree
/// with its shell's seed.
struct Shells {
    std::vector<std::vector<uint32_t>> triangles; ///< per shell
    std::vector<char> flipRelative;               ///< per triangle
};

/// An undirected edge's key.
uint64_t edgeKey(uint32_t a, uint32_t b)
{
    return (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
}

/// Does triangle t traverse the edge a -> b?
bool traverses(const Mesh& mesh, uint32_t t, uint32_t a, uint32_t b)
{
    const Vec3I& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k)
        if (tri[k] == a && tri[(k + 1) % 3] == b) return true;
    return false;
}

/// Breadth-first over manifold edges from each unvisited seed.
Shells findShells(const Mesh& mesh)
{
    const size_t n = mesh.triangles.size();
    // Edge to the triangles that use it, to find each triangle's neighbours.
    std::unordered_map<uint64_t, std::vector<uint32_t>> byEdge;
    byEdge.reserve(3 * n);
    for (uint32_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k)
            byEdge[edgeKey(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3])].push_back(t);
    Shells out;
    out.flipRelative.assign(n, 0);
    std::vector<int> shell(n, -1);
    for (uint32_t seed = 0; seed < n; ++seed) {
        if (shell[seed] >= 0) continue;
        const int id = int(out.triangles.size());
        out.triangles.emplace_back();
        std::vector<uint32_t> queue{seed};
        shell[seed] = id;
        for (size_t q = 0; q < queue.size(); ++q) {
            const uint32_t t = queue[q];
            out.triangles[id].push_back(t);
            const Vec3I& tri = mesh.triangles[t];
            for (int k = 0; k < 3; ++k) {
                // Orientation of t's edge as t will be after its relative flip.
                uint32_t a = tri[k], b = tri[(k + 1) % 3];
                if (out.flipRelative[t]) std::swap(a, b);
                const auto& users = byEdge[edgeKey(a, b)];
                if (users.size() != 2) continue; // boundary or non-manifold: no orientation to copy
                const uint32_t u = users[0] == t ? users[1] : users[0];
                if (shell[u] >= 0) continue;
                shell[u] = id;
                // Consistent neighbours traverse the shared edge the other way (b -> a).
                out.flipRelative[u] = traverses(mesh, u, a, b) ? 1 : 0;
                queue.push_back(u);
            }
        }
    }
    return out;
}

/// The signed volume of each shell (positive when outward).
std::vector<double> shellVolumes(const Mesh& mesh, const Shells& shells)
{
    std::vector<double> volume(shells.triangles.size(), 0.0);
    for (size_t s = 0; s < shells.triangles.size(); ++s)
        for (uint32_t t : shells.triangles[s]) {
            const Vec3I& tri = mesh.triangles[t];
            volume[s] += Vec3d(mesh.points[tri[0]])
                             .dot(Vec3d(mesh.points[tri[1]]).cross(Vec3d(mesh.points[tri[2]]))) /
                         6.0;
        }
    return volume;
}

/// Per shell of negative volume: does it lie inside another shell (by the winding number of each
/// other shell at one of its vertices)? Nesting is checked pairwise; beyond this many shells
/// (debris, particles) it is skipped and no shell counts as nested.
std::vector<char> nestedShells(const Mesh& mesh, const Shells& shells,
                               const std::vector<double>& volume)
{
    constexpr size_t kMaxNestingShells = 64;
    const size_t count = shells.triangles.size();
    std::vector<char> nested(count, 0);
    if (count > kMaxNestingShells) return nested;
    std::vector<WindingNumber> perShell;
    perShell.reserve(count);
    for (const auto& triangles : shells.triangles) {
        std::vector<Vec3I> tris;
        for (uint32_t t : triangles) tris.push_back(mesh.triangles[t]);
        perShell.emplace_back(mesh.points, std::move(tris));
    }
    for (size_t s = 0; s < count; ++s) {
        if (volume[s] >= 0.0) continue;
        const Vec3d probe(mesh.points[mesh.triangles[shells.triangles[s][0]][0]]);
        for (size_t o = 0; o < count && !nested[s]; ++o)
            nested[s] = o != s && std::abs(perShell[o](probe)) > 0.5;
    }
    return nested;
}

} // namespace

size_t repairOrientation(Mesh& mesh)
{
    const Shells shells = findShells(mesh);
    size_t flipped = 0;
    auto flip = [&mesh, &flipped](uint32_t t) {
        std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
        ++flipped;
    };
    // The majority orientation of each shell wins.
    for (const auto& triangles : shells.triangles) {
        size_t relative = 0;
        for (uint32_t t : triangles) relative += shells.flipRelative[t];
        const bool flipMarked = relative * 2 <= triangles.size();
        for (uint32_t t : triangles)
            if (bool(shells.flipRelative[t]) == flipMarked) flip(t);
    }
    // Inverted shells: negative volume and inside no other shell.
    const std::vector<double> volume = shellVolumes(mesh, shells);
    const std::vector<char> nested = nestedShells(mesh, shells, volume);
    for (size_t s = 0; s < shells.triangles.size(); ++s)
        if (volume[s] < 0.0 && !nested[s])
            for (uint32_t t : shells.triangles[s]) flip(t);
    analyzeTopology(mesh);
    return flipped;
}

} // namespace volmorph::detail
