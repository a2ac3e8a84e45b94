// Measures shared by the voxelization tests: a mesh's own volume, a voxelized volume, the overlap
// of two interiors; and a second shell appended to a mesh.
#pragma once

#include <volmorph/Mesh.h>
#include <volmorph/VolumeSet.h>

#include <cmath>
#include <utility>

namespace volmorph::test {

/// The volume a closed mesh encloses (world units cubed), by the divergence theorem.
inline double signedVolume(const Mesh& m)
{
    double v = 0.0;
    for (const Vec3I& t : m.triangles)
        v += Vec3d(m.points[t[0]]).dot(Vec3d(m.points[t[1]]).cross(Vec3d(m.points[t[2]]))) / 6.0;
    return v;
}

/// Enclosed world volume: the integral of density (tiles included). The ramp is centred on the
/// surface, so this is unbiased even where faces lie exactly on voxel centres, where counting
/// voxels with density > 0.5 is off by a layer.
inline double enclosedVolume(const VolumeSet& v)
{
    double sum = 0.0;
    for (auto it = v.density->cbeginValueOn(); it; ++it)
        sum += double(*it) * double(it.getVoxelCount());
    return sum * std::pow(v.voxelSize(), 3);
}

/// Intersection over union of the density > 0.5 regions of two grids on the same transform.
inline double insideIoU(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
{
    auto mask = [](const openvdb::FloatGrid& g) {
        openvdb::BoolGrid::Ptr m = openvdb::BoolGrid::create(false);
        for (auto it = g.cbeginValueOn(); it; ++it)
            if (*it > 0.5f) m->tree().fill(it.getBoundingBox(), true, true);
        return m;
    };
    openvdb::BoolGrid::Ptr ma = mask(a), mb = mask(b);
    const double countA = double(ma->activeVoxelCount()), countB = double(mb->activeVoxelCount());
    ma->tree().topologyIntersection(mb->tree());
    const double both = double(ma->activeVoxelCount());
    return both / (countA + countB - both);
}

/// Appends `other` to `mesh` (a second shell).
inline void append(Mesh& mesh, const Mesh& other, bool flip)
{
    const uint32_t offset = uint32_t(mesh.points.size());
    mesh.points.insert(mesh.points.end(), other.points.begin(), other.points.end());
    for (Vec3I t : other.triangles) {
        if (flip) std::swap(t[1], t[2]);
        mesh.triangles.push_back(Vec3I(t[0] + offset, t[1] + offset, t[2] + offset));
    }
    analyzeTopology(mesh);
}

} // namespace volmorph::test
