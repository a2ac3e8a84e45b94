// Small shots for the renderer's tests: a floor quad, a slab of fog, a sun.
#pragma once

#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include <openvdb/openvdb.h>

namespace volmorph::test {

/// An axis-aligned quad at height y over [x0, x1] x [z0, z1], facing up, colour (0.5, 0.6, 0.7).
inline render::PropMesh floorQuad(double y, double x0, double x1, double z0, double z1,
                                  render::PropMesh::Role role = render::PropMesh::Role::Diffuse)
{
    render::PropMesh m;
    m.points = {Vec3f(float(x0), float(y), float(z0)), Vec3f(float(x1), float(y), float(z0)),
                Vec3f(float(x1), float(y), float(z1)), Vec3f(float(x0), float(y), float(z1))};
    m.triangles = {Vec3I(0, 2, 1), Vec3I(0, 3, 2)};
    m.color = Vec3d(0.5, 0.6, 0.7);
    m.role = role;
    return m;
}

/// A fog of density 1 at the voxels (edge `voxel` world units) whose centres lie in the box
/// [lo, hi] (world units, rounded to voxel centres).
inline openvdb::FloatGrid::Ptr fogSlab(const Vec3d& lo, const Vec3d& hi, double voxel)
{
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    const openvdb::CoordBBox box(openvdb::Coord::round(lo / voxel),
                                 openvdb::Coord::round(hi / voxel));
    grid->tree().denseFill(box, 1.0f, true);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    return grid;
}

/// A directional light travelling along `travel`, white, of irradiance `intensity`.
inline render::Light sunLight(const Vec3d& travel, double intensity)
{
    render::Light light;
    light.direction = travel.unit();
    light.intensity = intensity;
    return light;
}

} // namespace volmorph::test
