// The sides stage's adapter for surface mode (blend.mode = "surface"): a scene's two meshes,
// imported with the scene's colours and put into correspondence (SurfaceMorph.h), and each frame's
// in-between with the scene's schedules applied: positions follow blend.sdf's schedule (the
// shape's, as in sdf mode), colours blend.color's; under the scene's [timing] each vertex at its
// own place's local time (SurfaceMorpher::frame with PlaceTimes).
#pragma once

#include <volmorph/Scene.h>
#include <volmorph/SurfaceMorph.h>
#include <volmorph/VolumeSet.h>
#include <volmorph/core/Interrupter.h>

#include <cstdint>
#include <memory>

namespace volmorph {

class LocalTime;

/// The in-between at t as `blend`'s schedules make it: everywhere at their tau, or under `timing`
/// (null or inactive: none) each place at the schedule of its own local time. Velocity in world
/// units per second of `secondsPerUnitT` (0: zero velocity).
SurfaceFrame surfaceFrameAt(const SurfaceMorpher& morpher, const BlendSpec& blend,
                            const LocalTime* timing, double t, double secondsPerUnitT);

class SceneSurface {
public:
    /// Imports both meshes (UserError at their `mesh` keys when they cannot be read) and puts them
    /// into correspondence (UserError at [surface] when it does not apply; Interrupted when
    /// `interrupter` asks to stop); reads the timing's regions at the scene's voxel size.
    explicit SceneSurface(const Scene& scene, Interrupter* interrupter = nullptr);

    /// Frame `frame`'s in-between; its velocity in world units per second (zero for a scene of one
    /// frame, where t stands still).
    SurfaceFrame frame(int frame) const;

    /// The in-between voxelized at the scene's voxel size (Voxelize.h: sdf, density, Cd) with its
    /// velocity as `vel` on the sdf's band (the vertex velocities interpolated at each voxel's
    /// closest surface point, as the colours are).
    VolumeSet voxels(const SurfaceFrame& frame, Interrupter* interrupter = nullptr,
                     uint64_t memoryLimitBytes = 0) const;

    const SurfaceMorpher& morpher() const { return mMorpher; }
    /// The scene's timing (null: none).
    const LocalTime* localTime() const { return mLocalTime.get(); }
    double voxelSize() const { return mVoxelSize; }

private:
    SceneSurface(const Scene& scene, std::pair<Mesh, Mesh> meshes, Interrupter* interrupter);

    BlendSpec mBlend;
    FramesSpec mFrames;
    double mVoxelSize = 0.0;
    SurfaceMorpher mMorpher;
    std::shared_ptr<const LocalTime> mLocalTime;
};

} // namespace volmorph
