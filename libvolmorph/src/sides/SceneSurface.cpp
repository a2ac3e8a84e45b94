#include <volmorph/SceneSurface.h>

#include <volmorph/LocalTime.h>
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

/// A place's time under `timing` with `schedule` applied (the chain rule through it).
PlaceTime placeTime(const LocalTime& timing, const ScheduleSpec& schedule, double t)
{
    return [&timing, &schedule, t](const Vec3d& x) {
        const LocalTau local = timing.at(x, t);
        const double slope = scheduleSlope(schedule, local.tau);
        return PlaceTau{scheduleValue(schedule, local.tau), slope * local.dt,
                        local.gradient * slope};
    };
}

} // namespace

SurfaceFrame surfaceFrameAt(const SurfaceMorpher& morpher, const BlendSpec& blend,
                            const LocalTime* timing, double t, double secondsPerUnitT)
{
    if (timing && timing->active()) {
        SurfaceFrame f =
            morpher.frame(placeTime(*timing, blend.sdf, t), placeTime(*timing, blend.color, t));
        const double scale = secondsPerUnitT > 0.0 ? 1.0 / secondsPerUnitT : 0.0;
        for (Vec3d& v : f.velocity) v *= scale;
        return f;
    }
    SurfaceFrame f = morpher.frame(scheduleValue(blend.sdf, t), scheduleValue(blend.color, t));
    // d x / d second = d x / d tau * d tau / d t / (seconds per unit of t)
    const double scale =
        secondsPerUnitT > 0.0 ? scheduleSlope(blend.sdf, t) / secondsPerUnitT : 0.0;
    for (Vec3d& v : f.velocity) v *= scale;
    return f;
}

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
    if (scene.timing.spread > 0.0)
        mLocalTime = std::make_shared<const LocalTime>(
            scene.timing, loadTimingRegions(scene, mVoxelSize, interrupter));
}

SurfaceFrame SceneSurface::frame(int frame) const
{
    return surfaceFrameAt(mMorpher, mBlend, mLocalTime.get(), mFrames.t(frame),
                          mFrames.secondsPerUnitT());
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
