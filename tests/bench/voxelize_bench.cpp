// Voxelization against OpenVDB's own path, side by side in one process:
//   anchor:   tools::meshToLevelSet + tools::sdfToFogVolume (what a user of OpenVDB would write)
//   volmorph: voxelize() (sdf + density with a centred ramp + colour grid)
// at 128, 256 and 512 voxels across; and volmorph's path for meshes still open after filling (the
// winding number evaluated), forced on the elephant with holes. Counters: active voxels of each
// grid, the sign path (0 flood fill, 1 closed shells, 2 winding number) and holes filled.
// Run: build-bench/tests/bench/volmorph_bench_voxelize --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true   (then tests/bench/ratios.py on the JSON output)
#include <volmorph/Voxelize.h>

#include <benchmark/benchmark.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>

#include <filesystem>
#include <map>

using namespace volmorph;

namespace {

const std::vector<std::string> kMeshes = {"bunny.obj", "knot1.off", "elephant.off",
                                          "elephant-with-holes.off", "bones.off"};
constexpr int64_t kOpenMesh = 3; // elephant-with-holes

const Mesh& mesh(size_t i)
{
    static std::map<size_t, Mesh> cache;
    auto it = cache.find(i);
    if (it == cache.end())
        it = cache
                 .emplace(i, importMesh(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" /
                                        "meshes" / kMeshes[i]))
                 .first;
    return it->second;
}

double voxelSizeFor(const Mesh& m, int across)
{
    VoxelizeOptions o;
    o.resolution = across;
    return resolveVoxelSize(m, o);
}

void openvdbLevelSetAndFog(benchmark::State& state)
{
    const Mesh& m = mesh(size_t(state.range(0)));
    const double voxelSize = voxelSizeFor(m, int(state.range(1)));
    const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    uint64_t active = 0;
    for (auto _ : state) {
        openvdb::FloatGrid::Ptr sdf =
            openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, m.points, m.triangles, 3.0f);
        openvdb::FloatGrid::Ptr fog = sdf->deepCopy();
        openvdb::tools::sdfToFogVolume(*fog);
        active = fog->activeVoxelCount();
        benchmark::DoNotOptimize(sdf);
    }
    state.counters["density_active"] = double(active);
    state.SetLabel(kMeshes[size_t(state.range(0))]);
}

void volmorphVoxelize(benchmark::State& state)
{
    const Mesh& m = mesh(size_t(state.range(0)));
    VoxelizeOptions o;
    o.voxelSize = voxelSizeFor(m, int(state.range(1)));
    VoxelizeStats stats;
    for (auto _ : state) {
        VolumeSet v = voxelize(m, o, nullptr, &stats);
        benchmark::DoNotOptimize(v);
    }
    state.counters["density_active"] = double(stats.densityActiveVoxels);
    state.counters["sdf_active"] = double(stats.sdfActiveVoxels);
    state.counters["sign_path"] = double(int(stats.signPath));
    state.counters["holes"] = double(stats.holesFilled);
    state.SetLabel(kMeshes[size_t(state.range(0))]);
}

/// The path for meshes still open after their holes are filled, forced on the elephant with holes.
void volmorphVoxelizeWindingNumber(benchmark::State& state)
{
    const Mesh& m = mesh(size_t(kOpenMesh));
    VoxelizeOptions o;
    o.voxelSize = voxelSizeFor(m, int(state.range(1)));
    o.sign = VoxelizeOptions::Sign::WindingNumber;
    VoxelizeStats stats;
    for (auto _ : state) {
        VolumeSet v = voxelize(m, o, nullptr, &stats);
        benchmark::DoNotOptimize(v);
    }
    state.counters["density_active"] = double(stats.densityActiveVoxels);
    state.SetLabel(kMeshes[size_t(kOpenMesh)]);
}

void openArguments(benchmark::internal::Benchmark* b)
{
    for (int64_t across : {128, 256, 512}) b->Args({kOpenMesh, across});
    b->Unit(benchmark::kMillisecond)->UseRealTime();
}

void arguments(benchmark::internal::Benchmark* b)
{
    for (int64_t m = 0; m < int64_t(kMeshes.size()); ++m)
        for (int64_t across : {128, 256, 512}) b->Args({m, across});
    b->Unit(benchmark::kMillisecond)->UseRealTime();
}

} // namespace

BENCHMARK(openvdbLevelSetAndFog)->Apply(arguments);
BENCHMARK(volmorphVoxelize)->Apply(arguments);
BENCHMARK(volmorphVoxelizeWindingNumber)->Apply(openArguments);
