// Both sides of a scene on one transform: meshes voxelized, volumes read and resampled.
#include <volmorph/SceneVolumes.h>

#include <volmorph/VolumeInput.h>
#include <volmorph/Voxelize.h>

#include <openvdb/tools/LevelSetRebuild.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace volmorph {

namespace {

SideExtent extentOf(const VolumeFileInfo& info)
{
    return SideExtent{info.worldMin, info.worldMax, info.voxelSize};
}

SideExtent extentOf(const Mesh& mesh)
{
    const auto [lo, hi] = mesh.bounds();
    return SideExtent{lo, hi, std::nullopt};
}

} // namespace

SceneMeshes importSceneMeshes(const Scene& scene)
{
    SceneMeshes out;
    std::vector<Diagnostic> problems;
    const std::pair<const ObjectSpec*, Mesh*> sides[2] = {{&scene.source, &out.source},
                                                          {&scene.target, &out.target}};
    for (const auto& [spec, mesh] : sides) {
        if (spec->isVolume()) continue;
        try {
            *mesh = importMesh(spec->mesh, spec->transform, spec->fileWhere);
        } catch (const UserError& e) {
            problems.insert(problems.end(), e.diagnostics().begin(), e.diagnostics().end());
        }
    }
    if (!problems.empty()) throw UserError(problems);
    return out;
}

std::pair<SideExtent, SideExtent> sceneExtents(const Scene& sequenced, const SceneMeshes& meshes)
{
    const Scene scene = sceneAtFrame(sequenced, sequenced.frames.first);
    auto extent = [](const ObjectSpec& spec, const Mesh& mesh) {
        return spec.isVolume() ? extentOf(inspectVolume(spec.volumeSource())) : extentOf(mesh);
    };
    return {extent(scene.source, meshes.source), extent(scene.target, meshes.target)};
}

double sceneVoxelSize(const VolumeSpec& volume, const SideExtent& source, const SideExtent& target)
{
    if (volume.voxelSize) return *volume.voxelSize;
    if (!volume.resolution && (source.inputVoxelSize || target.inputVoxelSize))
        return std::min(source.inputVoxelSize.value_or(target.inputVoxelSize.value_or(0.0)),
                        target.inputVoxelSize.value_or(source.inputVoxelSize.value_or(0.0)));
    const Vec3d extent = maxComponent(source.hi, target.hi) - minComponent(source.lo, target.lo);
    const double longest = std::max({extent.x(), extent.y(), extent.z()});
    return longest / double(std::max(1, volume.resolution.value_or(128)));
}

namespace {

/// One object at the scene's voxel size: a mesh voxelized, a volume read and resampled.
VolumeSet objectVolumes(const ObjectSpec& spec, const Mesh* mesh, const VolumeInput* input,
                        double voxelSize, bool needSdf, Interrupter* interrupter,
                        uint64_t memoryLimitBytes)
{
    if (input) {
        VolumeInputOptions o;
        o.voxelSize = voxelSize;
        o.needSdf = needSdf;
        o.memoryLimitBytes = memoryLimitBytes;
        return input->resample(o, interrupter);
    }
    VoxelizeOptions o;
    o.voxelSize = voxelSize;
    o.memoryLimitBytes = memoryLimitBytes;
    if (spec.color) o.color = Vec3f(*spec.color);
    return voxelize(*mesh, o, interrupter);
}

bool needsSdf(const Scene& scene)
{
    return scene.blend.mode == BlendMode::Sdf || scene.blend.mode == BlendMode::Variational;
}

} // namespace

SceneVolumes voxelizeScene(const Scene& sequenced, Interrupter* interrupter,
                           uint64_t memoryLimitBytes)
{
    const Scene scene = sceneAtFrame(sequenced, sequenced.frames.first);
    SceneVolumes out;
    out.meshes = importSceneMeshes(scene);
    // Each volume file is read once: its bounds and voxel size, then its grids.
    std::optional<VolumeInput> inputs[2];
    const ObjectSpec* specs[2] = {&scene.source, &scene.target};
    const Mesh* meshes[2] = {&out.meshes.source, &out.meshes.target};
    SideExtent extents[2];
    for (int i = 0; i < 2; ++i) {
        if (specs[i]->isVolume()) inputs[i].emplace(specs[i]->volumeSource());
        extents[i] = inputs[i] ? extentOf(inputs[i]->info()) : extentOf(*meshes[i]);
    }
    const double voxelSize = sceneVoxelSize(scene.volume, extents[0], extents[1]);
    VolumeSet* sides[2] = {&out.source, &out.target};
    for (int i = 0; i < 2; ++i)
        *sides[i] = objectVolumes(*specs[i], meshes[i], inputs[i] ? &*inputs[i] : nullptr,
                                  voxelSize, needsSdf(scene), interrupter, memoryLimitBytes);
    out.influences = voxelizeInfluences(scene, voxelSize, interrupter, memoryLimitBytes);
    out.timingRegions = loadTimingRegions(scene, voxelSize, interrupter, memoryLimitBytes);
    return out;
}

std::vector<TimedVolume> voxelizeInfluences(const Scene& scene, double voxelSize,
                                            Interrupter* interrupter, uint64_t memoryLimitBytes)
{
    std::vector<TimedVolume> out;
    if (scene.blend.mode != BlendMode::Variational) return out;
    for (const InfluenceSpec& influence : scene.influences) {
        std::optional<VolumeInput> input;
        Mesh mesh;
        if (influence.object.isVolume())
            input.emplace(influence.object.volumeSource());
        else
            mesh = importMesh(influence.object.mesh, influence.object.transform,
                              influence.object.fileWhere);
        out.push_back({objectVolumes(influence.object, &mesh, input ? &*input : nullptr, voxelSize,
                                     true, interrupter, memoryLimitBytes),
                       influence.t});
    }
    return out;
}

} // namespace volmorph

namespace volmorph {
namespace {

/// Region i's mesh, placed; UserError at its `mesh` key when it is not closed.
Mesh importRegionMesh(const Scene& scene, size_t i)
{
    const ObjectSpec& shape = scene.timingRegions[i].shape;
    Mesh mesh = importMesh(shape.mesh, shape.transform, shape.fileWhere);
    if (!mesh.report.watertight())
        throw UserError(shape.fileWhere,
                        "timing.region[" + std::to_string(i + 1) + "]: " + shape.mesh.string() +
                            " is not closed (" + std::to_string(mesh.report.boundaryEdges) +
                            " boundary edges, " + std::to_string(mesh.report.nonManifoldEdges) +
                            " non-manifold): a region needs a closed surface");
    return mesh;
}

} // namespace

void checkTimingRegions(const Scene& scene)
{
    for (size_t i = 0; i < scene.timingRegions.size(); ++i) {
        const ObjectSpec& shape = scene.timingRegions[i].shape;
        if (shape.isVolume())
            inspectVolume(shape.volumeSource());
        else
            importRegionMesh(scene, i);
    }
}

std::vector<TimingRegion> loadTimingRegions(const Scene& scene, double voxelSize,
                                            Interrupter* interrupter, uint64_t memoryLimitBytes)
{
    std::vector<TimingRegion> out;
    for (size_t i = 0; i < scene.timingRegions.size(); ++i) {
        const TimingRegionSpec& region = scene.timingRegions[i];
        const ObjectSpec& shape = region.shape;
        // The band reaches the softness, and two voxels more, outside.
        const float halfWidth =
            std::max(3.0f, float(std::ceil(region.softness / voxelSize)) + 2.0f);
        openvdb::FloatGrid::Ptr sdf;
        if (shape.isVolume()) {
            VolumeInputOptions o;
            o.voxelSize = voxelSize;
            o.needSdf = true;
            o.memoryLimitBytes = memoryLimitBytes;
            const VolumeSet v = VolumeInput(shape.volumeSource()).resample(o, interrupter);
            sdf = openvdb::tools::levelSetRebuild(*v.sdf, 0.0f, halfWidth, 3.0f);
        } else {
            const Mesh mesh = importRegionMesh(scene, i);
            VoxelizeOptions o;
            o.voxelSize = voxelSize;
            o.halfWidthVoxels = halfWidth;
            o.memoryLimitBytes = memoryLimitBytes;
            sdf = voxelize(mesh, o, interrupter).sdf;
        }
        // A hard edge (softness 0) is a voxel soft: the delay, and the in-between with it, stay
        // continuous, and the blend's bounds finite.
        out.push_back({sdf, region.start, std::max(region.softness, voxelSize)});
    }
    return out;
}

} // namespace volmorph
