// The topology of a level set's zero set (OpenVDB's volumeToMesh, then shells and the Euler
// characteristic of the triangulated mesh), and a torus's level set: for issue 40's checks on
// shape and topology.
#pragma once

#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <set>
#include <utility>
#include <vector>

namespace volmorph::test {

struct Topology {
    int components = 0;
    long euler = 0; ///< V - E + F of the triangulated zero set
};

inline Topology topologyOf(const openvdb::FloatGrid& grid)
{
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(grid, points, triangles, quads, 0.0);
    std::vector<std::array<uint32_t, 3>> faces;
    for (const auto& tri : triangles) faces.push_back({tri[0], tri[1], tri[2]});
    for (const auto& q : quads) {
        faces.push_back({q[0], q[1], q[2]});
        faces.push_back({q[0], q[2], q[3]});
    }
    std::vector<uint32_t> parent(points.size());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    std::set<std::pair<uint32_t, uint32_t>> edges;
    for (const auto& face : faces)
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = face[e], b = face[(e + 1) % 3];
            edges.insert({std::min(a, b), std::max(a, b)});
            parent[root(a)] = root(b);
        }
    Topology topology;
    for (uint32_t v = 0; v < parent.size(); ++v) topology.components += root(v) == v;
    topology.euler = long(points.size()) - long(edges.size()) + long(faces.size());
    return topology;
}

/// A torus about the y axis (major radius R, tube radius r): its exact signed distance in a band
/// of 3 voxels.
inline openvdb::FloatGrid::Ptr torusLevelSet(double R, double r, double voxel)
{
    const float band = float(3.0 * voxel);
    auto grid = openvdb::FloatGrid::create(band);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    auto acc = grid->getAccessor();
    const int n = int(std::ceil((R + r) / voxel)) + 4;
    for (int i = -n; i <= n; ++i)
        for (int j = -n; j <= n; ++j)
            for (int k = -n; k <= n; ++k) {
                const double x = i * voxel, y = j * voxel, z = k * voxel;
                const double d = std::hypot(std::hypot(x, z) - R, y) - r;
                if (std::abs(d) < band) acc.setValue(openvdb::Coord(i, j, k), float(d));
            }
    return grid;
}

} // namespace volmorph::test
