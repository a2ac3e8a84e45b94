// The warp and the morph frame, each beside its anchor in one process:
//  - exact vs approximated warp (tolerance 0.25 voxel) over the output domain of the default scene
//    at 256 voxels across, for 1, 4, 16 and 64 pairs (the scene's 3, plus hand-like random ones);
//    counter max_error_voxels is measured against the exact warp on every 3rd voxel;
//  - a whole frame (domain, warp, resample, blend) vs its lower bound: resampling source and target
//    once per output voxel of the same frame with the identity warp; in density mode (issue 4's
//    linear blend: morphFrameDensity, identityResampleDensity) and in the default scene's sdf mode
//    (issue 5: morphFrame, identityResample);
//  - frames at 128, 256 and 512 voxels across: time per active voxel.
// Run: build-bench/tests/bench/volmorph_bench_warp --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true
#include <volmorph/Morph.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/Voxelize.h>
#include <volmorph/Warp.h>

#include "warp/AdaptiveWarp.h"
#include "warp/VelocityKernel.h"
#include "warp/VelocityLeaf.h"

#include <benchmark/benchmark.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tree/LeafManager.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <random>

using namespace volmorph;

namespace {

const std::filesystem::path kScene =
    std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes" / "bunny-to-knot.toml";

Vec3d rotate(const Vec3d& v, const Vec3d& k, double angle)
{
    return v * std::cos(angle) + k.cross(v) * std::sin(angle) +
           k * (k.dot(v) * (1.0 - std::cos(angle)));
}

/// The default scene's pairs, cut to n or extended with random pairs of the kind a user places:
/// inside the bunny's bounds, moved by at most 0.15, turned by at most 45 degrees, scaled 0.7-1.4.
std::vector<FeaturePairSpec> pairsFor(const Scene& scene, int n)
{
    std::vector<FeaturePairSpec> pairs(
        scene.pairs.begin(), scene.pairs.begin() + std::min<size_t>(n, scene.pairs.size()));
    std::mt19937 random(1995);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto vec = [&] { return Vec3d(u(random), u(random), u(random)); };
    while (int(pairs.size()) < n) {
        FeaturePairSpec p;
        p.type = FeatureType(random() % 4);
        p.source.origin =
            Vec3d(-0.4, 0.05, -0.3) + Vec3d(0.8 * u(random), 0.85 * u(random), 0.6 * u(random));
        p.source.xAxis = (vec() - Vec3d(0.5)).unit();
        p.source.yAxis = p.source.xAxis.cross((vec() - Vec3d(0.5)).unit()).unit();
        p.source.zAxis = p.source.xAxis.cross(p.source.yAxis);
        p.source.scale = Vec3d(0.05) + vec() * 0.2;
        p.target = p.source;
        p.target.origin += (vec() - Vec3d(0.5)) * 0.3;
        const Vec3d axis = (vec() - Vec3d(0.5)).unit();
        const double angle = (u(random) - 0.5) * M_PI / 2;
        p.target.xAxis = rotate(p.source.xAxis, axis, angle);
        p.target.yAxis = rotate(p.source.yAxis, axis, angle);
        p.target.zAxis = p.target.xAxis.cross(p.target.yAxis);
        const Vec3d f = Vec3d(0.7) + vec() * 0.7;
        p.target.scale = Vec3d(p.source.scale.x() * f.x(), p.source.scale.y() * f.y(),
                               p.source.scale.z() * f.z());
        pairs.push_back(p);
    }
    return pairs;
}

struct Setup {
    Scene scene;
    SceneVolumes volumes;
};

const Setup& setup(int across)
{
    static std::map<int, Setup> cache;
    auto it = cache.find(across);
    if (it == cache.end()) {
        Setup s;
        s.scene = loadScene(kScene);
        s.scene.volume.voxelSize.reset();
        s.scene.volume.resolution = across;
        s.volumes = voxelizeScene(s.scene);
        it = cache.emplace(across, std::move(s)).first;
    }
    return it->second;
}

/// Reads every coordinate of a leaf's points, cheaply: the bits are xor-ed, which vectorizes (a
/// float sum would be a serial chain of 3072 additions, some 10% of the approximated warp's time,
/// measured as if it were the warp's).
uint32_t consume(const detail::WarpLeaf& leaf)
{
    uint32_t bits[8] = {};
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 512; i += 8)
            for (int l = 0; l < 8; ++l) {
                uint32_t a, b;
                std::memcpy(&a, &leaf.s[c][i + l], 4);
                std::memcpy(&b, &leaf.t[c][i + l], 4);
                bits[l] ^= a ^ b;
            }
    uint32_t all = 0;
    for (uint32_t b : bits) all ^= b;
    return all;
}

/// A hash of a leaf's origin and the bits of all its points (FNV-1a), summed over leaves so that
/// the order of the threads does not matter: equal hashes mean bit-identical warps.
uint64_t leafHash(const detail::WarpLeaf& leaf)
{
    uint64_t h = 1469598103934665603ull;
    auto mix = [&](uint32_t v) { h = (h ^ v) * 1099511628211ull; };
    mix(uint32_t(leaf.origin.x()));
    mix(uint32_t(leaf.origin.y()));
    mix(uint32_t(leaf.origin.z()));
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 512; ++i) {
            uint32_t a, b;
            std::memcpy(&a, &leaf.s[c][i], 4);
            std::memcpy(&b, &leaf.t[c][i], 4);
            mix(a);
            mix(b);
        }
    return h;
}

/// The warp alone over the frame's candidate domain: positions are computed and consumed.
/// The warp of a frame at t = 0.5 with `pairs` of pairsFor, 256 voxels across, in index space, and
/// the frame's candidate box.
struct FrameWarp {
    const Setup& s = setup(256);
    const openvdb::CoordBBox box;
    const InverseWarp warp;
    explicit FrameWarp(int pairs) : FrameWarp(pairsFor(setup(256).scene, pairs)) {}

private:
    explicit FrameWarp(const std::vector<FeaturePairSpec>& pairs)
        : box(Morpher(s.volumes.source, s.volumes.target, pairs, s.scene.warp, s.scene.blend)
                  .candidateBounds(0.5)),
          warp(pairs, s.scene.warp, 0.5, 1.0 / s.volumes.source.voxelSize())
    {
    }
};

void warpOnly(benchmark::State& state, double tolerance)
{
    const FrameWarp frame(int(state.range(0)));
    const Setup& s = frame.s;
    const openvdb::CoordBBox& box = frame.box;
    const InverseWarp& warp = frame.warp;
    const detail::Occupancy occS(s.volumes.source.density->tree()),
        occT(s.volumes.target.density->tree());
    const detail::AdaptiveWarp adaptive(warp, tolerance);
    detail::AdaptiveWarpStats stats;
    std::atomic<uint64_t> sink{0};
    for (auto _ : state) {
        stats = {};
        adaptive.forEachLeaf(
            box, &occS, &occT, [&](const detail::WarpLeaf& leaf) { sink += consume(leaf); },
            &stats);
    }
    state.counters["leaves"] = double(stats.leaves);
    state.counters["exact_evals"] = double(stats.exactEvaluations);
    state.counters["near_evals"] = double(stats.nearEvaluations);
    if (tolerance > 0.0) {
        // The error actually made, against the exact warp, on every 3rd voxel of the domain.
        std::mutex m;
        double worst = 0.0;
        std::atomic<uint64_t> hash{0};
        adaptive.forEachLeaf(box, &occS, &occT, [&](const detail::WarpLeaf& leaf) {
            hash += leafHash(leaf);
            double local = 0.0;
            Vec3d ps, pt;
            for (int i = 0; i < 512; i += 3) {
                warp.map(leaf.origin.offsetBy(i >> 6, (i >> 3) & 7, i & 7).asVec3d(), ps, pt);
                local = std::max({local, (Vec3d(leaf.source(i)) - ps).length(),
                                  (Vec3d(leaf.target(i)) - pt).length()});
            }
            std::lock_guard<std::mutex> lock(m);
            worst = std::max(worst, local);
        });
        state.counters["max_error_voxels"] = worst;
        state.counters["measured_error_voxels"] = stats.maxErrorVoxels;
        // The low 32 bits, exact in a double counter; compare runs before and after a change.
        state.counters["points_hash"] = double(hash.load() & 0xffffffffu);
    }
}

void exactWarp(benchmark::State& state)
{
    warpOnly(state, 0.0);
}
void approximatedWarp(benchmark::State& state)
{
    warpOnly(state, 0.25);
}

/// The warp's exact velocities, both sides (the velocity's hot loop), at 4096 points of the frame's
/// candidate box at t = 0.5 with range(0) pairs: InverseWarp::derivatives and ::velocity (range(1)
/// = 0) and the vector kernel (1, all points in one call, 8 to a vector), in nanoseconds per point,
/// one thread.
void warpVelocities(benchmark::State& state)
{
    const FrameWarp frame(int(state.range(0)));
    const openvdb::CoordBBox& box = frame.box;
    const InverseWarp& warp = frame.warp;
    const detail::VelocityKernel kernel(warp, detail::VelocityLeaf::kExactWithin);
    std::mt19937 random(3);
    std::vector<Vec3d> points(4096);
    for (Vec3d& p : points)
        for (int a = 0; a < 3; ++a)
            p[a] = std::uniform_real_distribution<double>(box.min()[a], box.max()[a])(random);
    std::vector<Vec3d> vs(points.size()), vt(points.size());
    std::unique_ptr<bool[]> regular(new bool[points.size()]);
    double sink = 0.0;
    for (auto _ : state) {
        if (state.range(1)) {
            kernel.velocities(points.data(), points.size(), vs.data(), vt.data(), regular.get());
        } else {
            for (size_t i = 0; i < points.size(); ++i) {
                InverseWarp::Derivatives ds, dt;
                warp.derivatives(points[i], ds, dt);
                regular[i] = InverseWarp::velocity(ds, vs[i]) & InverseWarp::velocity(dt, vt[i]);
            }
        }
        sink += vs[0].x() + vt.back().y();
    }
    benchmark::DoNotOptimize(sink);
    state.counters["ns_per_point"] = benchmark::Counter(
        double(points.size()) * 1e-9,
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

/// One whole frame at t = 0.5 with the scene's pairs (or `pairs` of pairsFor), in the given blend
/// mode, at range(0) voxels across (or 256 when `pairs` is given).
void frame(benchmark::State& state, BlendMode mode, int pairs = 0, MorphOptions options = {})
{
    const Setup& s = setup(pairs ? 256 : int(state.range(0)));
    BlendSpec blend = s.scene.blend;
    blend.mode = mode;
    const Morpher morpher(s.volumes.source, s.volumes.target,
                          pairs ? pairsFor(s.scene, pairs) : s.scene.pairs, s.scene.warp, blend,
                          options);
    MorphStats stats;
    for (auto _ : state) {
        VolumeSet v = morpher.frame(0.5, &stats);
        benchmark::DoNotOptimize(v);
    }
    state.counters["active_voxels"] = double(stats.activeVoxels);
    state.counters["candidate_leaves"] = double(stats.candidateLeaves);
    state.counters["output_leaves"] = double(stats.outputLeaves);
    if (mode == BlendMode::Sdf) state.counters["blend_samples"] = double(stats.blendSamples);
    state.counters["ns_per_active_voxel"] = benchmark::Counter(
        double(stats.activeVoxels) * 1e-9,
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    if (options.secondsPerUnitT > 0.0) {
        state.counters["vel_interpolated_cubes"] = double(stats.velocityInterpolated);
        state.counters["vel_exact_cubes"] = double(stats.velocityExact);
    }
}

/// The default scene's frame (sdf mode: the blend of extended distances, its islands dropped,
/// redistanced; issue 5).
void morphFrame(benchmark::State& state)
{
    frame(state, BlendMode::Sdf);
}
/// The frame of issue 4: domain, warp, resample, and a linear blend of density and of
/// density-weighted colour.
void morphFrameDensity(benchmark::State& state)
{
    frame(state, BlendMode::Density);
}

/// The lower bound of a frame: every output voxel of the same frame (in the given mode) resampled
/// from source and target at its own position (identity warp) and blended, in parallel over leaves.
void lowerBound(benchmark::State& state, BlendMode mode)
{
    const Setup& s = setup(int(state.range(0)));
    BlendSpec blend = s.scene.blend;
    blend.mode = mode;
    const Morpher morpher(s.volumes.source, s.volumes.target, s.scene.pairs, s.scene.warp, blend);
    VolumeSet out = morpher.frame(0.5);
    // Every output voxel counts, also those the frame stored as tiles afterwards.
    out.density->tree().voxelizeActiveTiles();
    out.color->tree().voxelizeActiveTiles();
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(out.density->tree());
    auto colors = out.color;
    const VolumeSet& src = s.volumes.source;
    const VolumeSet& dst = s.volumes.target;
    for (auto _ : state) {
        leaves.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
            auto ds = src.density->getConstAccessor(), dt = dst.density->getConstAccessor();
            auto cs = src.color->getConstAccessor(), ct = dst.color->getConstAccessor();
            auto* color = colors->tree().probeLeaf(leaf.origin());
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const openvdb::Vec3R p = it.getCoord().asVec3d();
                const float a = openvdb::tools::BoxSampler::sample(ds, p);
                const float b = openvdb::tools::BoxSampler::sample(dt, p);
                it.setValue(0.5f * a + 0.5f * b);
                if (color && a + b > 0.0f)
                    color->setValueOnly(it.pos(), (a * openvdb::tools::BoxSampler::sample(cs, p) +
                                                   b * openvdb::tools::BoxSampler::sample(ct, p)) /
                                                      (a + b));
            }
        });
    }
    state.counters["active_voxels"] = double(out.density->activeVoxelCount());
}

/// A frame at t = 0.5 whose sides carry extra grids (issue 35: at most 1.3x per extra grid):
/// range(1) float grids and range(2) vec3 grids, each a copy of the side's density (the shape a
/// temperature or a velocity has: where the density is). range(3): 0 density mode, 1 sdf mode.
void morphFrameExtras(benchmark::State& state)
{
    const Setup& s = setup(int(state.range(0)));
    VolumeSet source = s.volumes.source, target = s.volumes.target;
    for (VolumeSet* v : {&source, &target}) {
        for (int i = 0; i < state.range(1); ++i)
            v->extras["float" + std::to_string(i)] = v->density->deepCopy();
        for (int i = 0; i < state.range(2); ++i) {
            auto g = openvdb::Vec3SGrid::create(Vec3f(0.0f));
            g->setTransform(v->density->transform().copy());
            g->tree().topologyUnion(v->density->tree());
            for (auto it = g->tree().beginValueOn(); it; ++it) it.setValue(Vec3f(0.0f, 1.0f, 0.5f));
            v->extras["vec" + std::to_string(i)] = g;
        }
    }
    BlendSpec blend = s.scene.blend;
    blend.mode = state.range(3) ? BlendMode::Sdf : BlendMode::Density;
    const Morpher morpher(source, target, s.scene.pairs, s.scene.warp, blend);
    MorphStats stats;
    for (auto _ : state) {
        VolumeSet v = morpher.frame(0.5, &stats);
        benchmark::DoNotOptimize(v);
    }
    state.counters["active_voxels"] = double(stats.activeVoxels);
}

/// A frame at t = 0.5 with range(0) pairs (the scene's, then random ones), without (range(1) = 0)
/// and with the `vel` grid (issue 36: at most 1.3x), in density (range(2) = 0) or sdf mode.
void morphFrameVelocity(benchmark::State& state)
{
    MorphOptions options;
    options.secondsPerUnitT = state.range(1) ? 1.0 : 0.0;
    frame(state, state.range(2) ? BlendMode::Sdf : BlendMode::Density, int(state.range(0)),
          options);
}

void identityResample(benchmark::State& state)
{
    lowerBound(state, BlendMode::Sdf);
}
void identityResampleDensity(benchmark::State& state)
{
    lowerBound(state, BlendMode::Density);
}

} // namespace

/// 1, 4, 16 and 64 pairs, in milliseconds of wall time.
void pairCounts(benchmark::internal::Benchmark* b)
{
    b->Arg(1)->Arg(4)->Arg(16)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(exactWarp)->Apply(pairCounts);
BENCHMARK(approximatedWarp)->Apply(pairCounts);
/// 128, 256 and 512 voxels across, in milliseconds of wall time.
void resolutions(benchmark::internal::Benchmark* b)
{
    b->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(morphFrame)->Apply(resolutions);
BENCHMARK(morphFrameDensity)->Apply(resolutions);
BENCHMARK(identityResample)->Apply(resolutions);
BENCHMARK(identityResampleDensity)->Apply(resolutions);
/// 256 across; no extra grid, one float, two floats, one vec3; density and sdf mode.
void extraGrids(benchmark::internal::Benchmark* b)
{
    for (int sdf : {0, 1})
        for (auto [floats, vectors] : {std::pair{0, 0}, {1, 0}, {2, 0}, {0, 1}})
            b->Args({256, floats, vectors, sdf});
    b->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(morphFrameExtras)->Apply(extraGrids);
/// The scene's 3 pairs and 16 pairs, without and with velocity, density and sdf mode.
BENCHMARK(warpVelocities)->ArgsProduct({{3, 16, 64}, {0, 1}})->Unit(benchmark::kMicrosecond);
BENCHMARK(morphFrameVelocity)
    ->ArgsProduct({{3, 16}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
