// volmorph's sdf-mode morph beside OpenVDB's tools::LevelSetMorphing (the level-set morph of
// Houdini's VDB Morph SDF), over the same sequence, in one process:
//   a sphere (genus 0) into the torus knot (genus 1), 128 voxels across, 24 intervals;
//   volmorph: Morpher::frame(t) at t = i / 24 (sdf mode, no pairs: a pure shape blend);
//   LevelSetMorphing: the sphere advected toward the knot, advect(0, dt) per interval, dt = 0.25
//   (its speed is the target's distance, so the gap shrinks like e^-t: 24 intervals of 0.25 leave
//   e^-6 of it), first-order upwind in space, TVD-RK1 in time (its fastest settings).
// Reports the median time per frame/interval over 3 runs and, for the last frame, the voxels whose
// sign disagrees with the target's sdf, as a share of the voxels inside either shape.
// Run: build-bench/tests/bench/volmorph_bench_levelset_morph
#include <volmorph/Mesh.h>
#include <volmorph/Morph.h>
#include <volmorph/Voxelize.h>

#include <openvdb/tools/LevelSetMorph.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <vector>

using namespace volmorph;

namespace {

const std::filesystem::path kMeshes =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";
constexpr int kIntervals = 24;
constexpr int kRuns = 3;

double seconds(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// Voxels (over the box of both) whose inside/outside differs between `a` and `target`, divided by
/// the voxels inside either.
double signMismatch(const openvdb::FloatGrid& a, const openvdb::FloatGrid& target)
{
    openvdb::CoordBBox box = a.evalActiveVoxelBoundingBox();
    box.expand(target.evalActiveVoxelBoundingBox());
    auto pa = a.getConstAccessor();
    auto pt = target.getConstAccessor();
    uint64_t differ = 0, inside = 0;
    for (auto c = box.begin(); c; ++c) {
        const bool ia = pa.getValue(*c) < 0.0f, it = pt.getValue(*c) < 0.0f;
        differ += ia != it;
        inside += ia || it;
    }
    return inside ? double(differ) / double(inside) : 0.0;
}

} // namespace

int main()
{
    openvdb::initialize();
    VoxelizeOptions options;
    options.voxelSize = 1.0 / 128.0; // the sphere is 1 world unit across: 128 voxels
    const VolumeSet sphere = voxelize(importMesh(kMeshes / "sphere.obj"), options);
    const VolumeSet knot = voxelize(importMesh(kMeshes / "knot1.off"), options);
    std::printf(
        "sphere -> knot at voxel %.5f world units (128 across), %d intervals, median of %d runs\n",
        *options.voxelSize, kIntervals, kRuns);

    std::vector<double> oursSetup, oursFrame, lsmFrame;
    double oursMismatch = 0.0, lsmMismatch = 0.0;
    for (int run = 0; run < kRuns; ++run) {
        BlendSpec blend;
        blend.mode = BlendMode::Sdf;
        auto start = std::chrono::steady_clock::now();
        const Morpher morpher(sphere, knot, {}, WarpSpec{}, blend);
        oursSetup.push_back(seconds(start));
        start = std::chrono::steady_clock::now();
        VolumeSet last;
        for (int i = 1; i <= kIntervals; ++i) last = morpher.frame(double(i) / kIntervals);
        oursFrame.push_back(seconds(start) / kIntervals);
        oursMismatch = signMismatch(*last.sdf, *knot.sdf);

        openvdb::FloatGrid::Ptr moving = sphere.sdf->deepCopy();
        openvdb::tools::LevelSetMorphing<openvdb::FloatGrid> lsm(*moving, *knot.sdf);
        lsm.setSpatialScheme(openvdb::math::FIRST_BIAS);
        lsm.setTemporalScheme(openvdb::math::TVD_RK1);
        start = std::chrono::steady_clock::now();
        for (int i = 0; i < kIntervals; ++i) lsm.advect(0.0, 0.25);
        lsmFrame.push_back(seconds(start) / kIntervals);
        lsmMismatch = signMismatch(*moving, *knot.sdf);
        std::printf(
            "  run %d: volmorph %.3f s/frame (+ %.2f s once), LevelSetMorphing %.3f s/interval\n",
            run + 1, oursFrame.back(), oursSetup.back(), lsmFrame.back());
    }
    const double ours = median(oursFrame), setup = median(oursSetup), theirs = median(lsmFrame);
    std::printf("volmorph sdf mode     %.3f s per frame, %.2f s once per sequence; last frame sign "
                "mismatch %.3f%%\n",
                ours, setup, 100.0 * oursMismatch);
    std::printf("LevelSetMorphing      %.3f s per interval; last frame sign mismatch %.3f%%\n",
                theirs, 100.0 * lsmMismatch);
    std::printf("ratio per frame %.1fx; over the whole sequence (setup included) %.1fx\n",
                theirs / ours, theirs * kIntervals / (ours * kIntervals + setup));
    return 0;
}
