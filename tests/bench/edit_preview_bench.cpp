// What the feature-pair editor (issue 39) must redo after a drag, before the page can show the new
// in-between: the default scene at 128 voxels across (voxelized once, as the editor keeps it), one
// pair's target origin moved, then
//  - Setup: a Morpher built with the edited pairs (sdf mode: its extended distances);
//  - Frame: the in-between at t = 0.5;
//  - Mesh: its surface by OpenVDB's volumeToMesh (the sdf's zero level set), what the page draws;
//  - Whole: the three in a row (the bound: 1 s, median of 5, 2 cores);
//  - KeptSetup: the same with the editor's Morpher kept and its pairs changed (Morpher::withPairs).
// Run: build/tests/bench/volmorph_bench_edit_preview --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true
#include <volmorph/Morph.h>
#include <volmorph/SceneVolumes.h>

#include <benchmark/benchmark.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <filesystem>
#include <optional>

using namespace volmorph;

namespace {

struct Setup {
    Scene scene;
    SceneVolumes volumes;
};

const Setup& setup()
{
    static std::optional<Setup> s;
    if (!s) {
        s.emplace();
        s->scene =
            loadScene(std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml");
        s->scene.volume.voxelSize.reset();
        s->scene.volume.resolution = 128;
        s->volumes = voxelizeScene(s->scene);
    }
    return *s;
}

/// The scene's pairs with pair 2's target origin dragged by `step` world units along x.
std::vector<FeaturePairSpec> dragged(double step)
{
    std::vector<FeaturePairSpec> pairs = setup().scene.pairs;
    pairs[1].target.origin += Vec3d(step, 0.0, 0.0);
    return pairs;
}

Morpher morpher(double step)
{
    const Setup& s = setup();
    return Morpher(s.volumes.source, s.volumes.target, dragged(step), s.scene.warp, s.scene.blend);
}

size_t triangles(const VolumeSet& v)
{
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> tris;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*v.sdf, points, tris, quads, 0.0, 0.0);
    return tris.size() + 2 * quads.size();
}

void EditSetup(benchmark::State& state)
{
    setup();
    double step = 0.0;
    for (auto _ : state) benchmark::DoNotOptimize(morpher(step += 1e-3));
}

void EditFrame(benchmark::State& state)
{
    const Morpher m = morpher(0.01);
    for (auto _ : state) benchmark::DoNotOptimize(m.frame(0.5));
}

void EditMesh(benchmark::State& state)
{
    const VolumeSet v = morpher(0.01).frame(0.5);
    size_t n = 0;
    for (auto _ : state) n = triangles(v);
    state.counters["triangles"] = double(n);
}

void EditWhole(benchmark::State& state)
{
    setup();
    double step = 0.0;
    size_t n = 0;
    for (auto _ : state) n = triangles(morpher(step += 1e-3).frame(0.5));
    state.counters["triangles"] = double(n);
}

/// The same with the setup kept: Morpher::withPairs on the editor's Morpher.
void EditKept(benchmark::State& state)
{
    const Morpher kept = morpher(0.0);
    double step = 0.0;
    size_t n = 0;
    for (auto _ : state) n = triangles(kept.withPairs(dragged(step += 1e-3)).frame(0.5));
    state.counters["triangles"] = double(n);
}

} // namespace

BENCHMARK(EditSetup)->Name("EditPreview/Setup")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(EditFrame)->Name("EditPreview/Frame")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(EditMesh)->Name("EditPreview/Mesh")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(EditWhole)->Name("EditPreview/Whole")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(EditKept)->Name("EditPreview/KeptSetup")->Unit(benchmark::kMillisecond)->UseRealTime();
