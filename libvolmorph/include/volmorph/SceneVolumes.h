// The sides stage: the adapter from a Scene to the stages that make volumes (mesh/, voxelize/,
// volume/), which take their own options. A scene's two sides as voxels on one shared transform:
// each side's mesh voxelized (Voxelize.h) or its volume file read and resampled (VolumeInput.h), at
// the scene's voxel size.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/Mesh.h>
#include <volmorph/LocalTime.h>
#include <volmorph/Scene.h>
#include <volmorph/VolumeSet.h>

#include <cstdint>
#include <optional>

namespace volmorph {

/// A scene's two meshes, imported with their transforms (empty for a side that is a volume).
struct SceneMeshes {
    Mesh source, target;
};

/// Imports both meshes of `scene`; problems with either are all reported in one UserError, each
/// at the scene's `mesh` key.
SceneMeshes importSceneMeshes(const Scene& scene);

/// One side's world bounds, and for a volume its finest voxel size (world units), known before
/// voxelizing.
struct SideExtent {
    Vec3d lo{0.0}, hi{0.0};
    std::optional<double> inputVoxelSize;
};

/// The extents of both sides: a mesh's bounds from `meshes` (imported), a volume's from its file (a
/// sequence's at the scene's first frame).
std::pair<SideExtent, SideExtent> sceneExtents(const Scene& scene, const SceneMeshes& meshes);

/// A scene's voxel size in world units: volume.voxel_size; or volume.resolution voxels across the
/// longest side of both sides' bounds together (both share one grid); or, with neither (a scene
/// with a volume input may leave out [volume]), the finest input volume's voxel size.
double sceneVoxelSize(const VolumeSpec& volume, const SideExtent& source, const SideExtent& target);

/// A scene's source and target on one shared transform, with the scene's colours.
struct SceneVolumes {
    SceneMeshes meshes; ///< the imported meshes (empty for a volume side)
    VolumeSet source, target;
    /// Variational mode's influence shapes on the same transform, each with its time.
    std::vector<TimedVolume> influences;
    /// [[timing.region]]s: each one's signed distance, valid to its softness and more outside.
    std::vector<TimingRegion> timingRegions;
};

/// Imports and voxelizes (or reads) both sides of `scene` (the same code as `volmorph voxelize`);
/// a sequence at the scene's first frame (sceneAtFrame() picks another). In sdf and variational
/// modes a fog volume gets a derived level set (VolumeInput.h). The influence shapes too.
SceneVolumes voxelizeScene(const Scene& scene, Interrupter* interrupter = nullptr,
                           uint64_t memoryLimitBytes = 0);

/// Variational mode's influence shapes (none in another mode), voxelized or read at `voxelSize`,
/// each with a level set.
std::vector<TimedVolume> voxelizeInfluences(const Scene& scene, double voxelSize,
                                            Interrupter* interrupter = nullptr,
                                            uint64_t memoryLimitBytes = 0);

/// The scene's [[timing.region]]s at `voxelSize`: a mesh (which must be closed: UserError at its
/// `mesh` key otherwise) voxelized, a fog mask read and its 0.5 level made a level set, each with
/// a band that reaches its softness (and two voxels more) outside. A softness below a voxel is
/// taken as one voxel.
/// Checks each region's file without voxelizing it: a mesh imported (and closed), a volume's
/// header read. UserError at its key otherwise.
void checkTimingRegions(const Scene& scene);

std::vector<TimingRegion> loadTimingRegions(const Scene& scene, double voxelSize,
                                            Interrupter* interrupter = nullptr,
                                            uint64_t memoryLimitBytes = 0);

} // namespace volmorph
