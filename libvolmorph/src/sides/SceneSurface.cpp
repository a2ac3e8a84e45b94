#include <volmorph/SceneSurface.h>

#include <volmorph/SceneVolumes.h>
#include <volmorph/Schedule.h>
#include <volmorph/Voxelize.h>

namespace volmorph {
namespace {

/// A side's colour as the scene gives it: `color` over every vertex, else the file's own.
Mesh coloured(Mesh mesh, const ObjectSpec& spec)
{
    if (spec.color) mesh.colors.assign(mesh.points.size(), Vec3f(*spec.color));
    return mesh;
}

SideExtent extentOf(const Mesh& mesh)
{
    const auto [lo, hi] = mesh.bounds();
    return {lo, hi, {}};
}

std::pair<Mesh, Mesh> sceneMeshes(const Scene& scene)
{
    SceneMeshes meshes = importSceneMeshes(scene);
    return {coloured(std::move(meshes.source), scene.source),
            coloured(std::move(meshes.target), scene.target)};
}

} // namespace

SceneSurface::SceneSurface(const Scene& scene, Interrupter* interrupter)
    : SceneSurface(scene, sceneMeshes(scene), interrupter)
{
}

SceneSurface::SceneSurface(const Scene& scene, std::pair<Mesh, Mesh> meshes,
                           Interrupter* interrupter)
    : mBlend(scene.blend), mFrames(scene.frames),
      mVoxelSize(sceneVoxelSize(scene.volume, extentOf(meshes.first), extentOf(meshes.second))),
      mMorpher(std::move(meshes.first), std::move(meshes.second), scene.surface, interrupter)
{
}

SurfaceFrame SceneSurface::frame(int frame) const
{
    const double t = mFrames.t(frame);
    SurfaceFrame f = mMorpher.frame(scheduleValue(mBlend.sdf, t), scheduleValue(mBlend.color, t));
    // d x / d second = d x / d tau * d tau / d t / (seconds per unit of t)
    const double seconds = mFrames.secondsPerUnitT();
    const double scale = seconds > 0.0 ? scheduleSlope(mBlend.sdf, t) / seconds : 0.0;
    for (Vec3d& v : f.velocity) v *= scale;
    return f;
}

VolumeSet SceneSurface::voxels(const SurfaceFrame& frame, Interrupter* interrupter,
                               uint64_t memoryLimitBytes) const
{
    VoxelizeOptions o;
    o.voxelSize = mVoxelSize;
    o.memoryLimitBytes = memoryLimitBytes;
    o.vertexVelocity.reserve(frame.velocity.size());
    for (const Vec3d& v : frame.velocity) o.vertexVelocity.emplace_back(Vec3f(v));
    return voxelize(frame.mesh(), o, interrupter);
}

} // namespace volmorph
