// Issue 38's accuracy check of sdf mode's extended distances (blend/ExtendedDistance.h), not a
// test: the default scene at N voxels across (default 250), frames at 5 values of t. At every voxel
// of each frame's blended band (|sdf| below the band's half width), the blend the frame is made of,
//   (1 - tau) d_S(W_S(x)) + tau d_T(W_T(x)),
// read from the extended fields is compared with the same blend read from a dense reference:
// each mesh's exact distances at 1-voxel spacing over the whole box (OpenVDB's meshToVolume with a
// band as wide as the box: the distance to the closest triangle at every voxel). Both are read
// trilinearly at the warped points, through the same exact warp. Prints, per t, the mean,
// the 99.9th percentile and the largest difference in voxels, and the share of voxels over 0.25
// voxel.
//
// usage: volmorph_bench_far_field [N]   (N voxels across; 250 by default)
#include "blend/ExtendedDistance.h" // private to the library

#include <volmorph/Mesh.h>
#include <volmorph/Morph.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/Schedule.h>
#include <volmorph/Voxelize.h>
#include <volmorph/Warp.h>

#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <vector>

using namespace volmorph;

namespace {

const std::filesystem::path kScene =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml";

/// A mesh's distances at every voxel of `box` (world units): a band as wide as the box.
openvdb::FloatGrid::Ptr exactDistances(const Mesh& mesh, double voxel,
                                       const openvdb::CoordBBox& box)
{
    VoxelizeOptions options;
    options.voxelSize = voxel;
    const openvdb::Coord dim = box.dim();
    options.halfWidthVoxels = float(std::max({dim.x(), dim.y(), dim.z()}));
    options.memoryLimitBytes = 16ull << 30;
    return voxelize(mesh, options).sdf;
}

struct Row {
    double t = 0.0, worst = 0.0, p999 = 0.0, mean = 0.0;
    size_t voxels = 0, outside = 0, over = 0; ///< over: beyond 0.25 voxel
};

Row compare(const Scene& scene, const SceneVolumes& volumes, const Morpher& morpher,
            const detail::ExtendedDistance& farS, const detail::ExtendedDistance& farT,
            const openvdb::FloatGrid& refS, const openvdb::FloatGrid& refT, double t)
{
    const double voxel = volumes.source.voxelSize();
    const VolumeSet frame = morpher.frame(t);
    const InverseWarp warp(scene.pairs, scene.warp, t, 1.0 / voxel);
    const float tau = float(scheduleValue(scene.blend.sdf, t));
    const float width = frame.sdf->background();
    detail::ExtendedDistance::Reader<openvdb::tools::BoxSampler> a(farS), b(farT);
    const openvdb::FloatGrid::ConstAccessor accS = refS.getConstAccessor(),
                                            accT = refT.getConstAccessor();
    openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> ra(
        accS, refS.transform()),
        rb(accT, refT.transform());
    const openvdb::CoordBBox boxS = refS.evalActiveVoxelBoundingBox(),
                             boxT = refT.evalActiveVoxelBoundingBox();
    std::vector<double> errors;
    Row row;
    row.t = t;
    for (auto it = frame.sdf->cbeginValueOn(); it; ++it) {
        if (!(std::abs(*it) < width)) continue;
        Vec3d ps, pt;
        warp.map(it.getCoord().asVec3d(), ps, pt);
        if (!boxS.isInside(openvdb::Coord::round(ps)) ||
            !boxT.isInside(openvdb::Coord::round(pt))) {
            ++row.outside;
            continue;
        }
        const double ours = (1.0 - tau) * a(ps) + tau * b(pt);
        const double ref = (1.0 - tau) * ra.isSample(ps) + tau * rb.isSample(pt);
        errors.push_back(std::abs(ours - ref) / voxel);
    }
    row.voxels = errors.size();
    if (errors.empty()) return row;
    std::sort(errors.begin(), errors.end());
    row.worst = errors.back();
    row.p999 = errors[size_t(0.999 * double(errors.size() - 1))];
    for (double e : errors) row.mean += e / double(errors.size());
    row.over = size_t(errors.end() - std::upper_bound(errors.begin(), errors.end(), 0.25));
    return row;
}

} // namespace

int main(int argc, char** argv)
{
    openvdb::initialize();
    const int across = argc > 1 ? std::atoi(argv[1]) : 250;
    Scene scene = loadScene(kScene);
    scene.volume.voxelSize = 1.0 / across;
    scene.volume.resolution.reset();
    scene.blend.mode = BlendMode::Sdf;
    const SceneVolumes volumes = voxelizeScene(scene);
    const double voxel = volumes.source.voxelSize();
    const openvdb::CoordBBox box = detail::ExtendedDistance::boxFor(
        *volumes.source.sdf, *volumes.target.sdf, scene.pairs.size());
    const auto madeS = detail::ExtendedDistance::make(volumes.source.sdf, box, nullptr);
    const auto madeT = detail::ExtendedDistance::make(volumes.target.sdf, box, nullptr);
    const detail::ExtendedDistance &farS = *madeS, &farT = *madeT;
    std::printf("default scene at %d voxels across (voxel %.5g); reference over %d x %d x %d\n",
                across, voxel, box.dim().x(), box.dim().y(), box.dim().z());
    const auto refS = exactDistances(volumes.meshes.source, voxel, box);
    const auto refT = exactDistances(volumes.meshes.target, voxel, box);
    const Morpher morpher(volumes.source, volumes.target, scene.pairs, scene.warp, scene.blend);
    std::printf(
        "| t | band voxels | outside the reference | mean | 99.9%% | largest | over 0.25 |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
    for (const double t : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        const Row r = compare(scene, volumes, morpher, farS, farT, *refS, *refT, t);
        std::printf("| %.1f | %zu | %zu | %.3f | %.3f | %.3f | %.3f%% |\n", r.t, r.voxels,
                    r.outside, r.mean, r.p999, r.worst, 100.0 * double(r.over) / double(r.voxels));
        std::fflush(stdout);
    }
    return 0;
}
