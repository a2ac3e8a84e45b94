// Issue 40's frame cost: a variational frame against an sdf-mode frame of the same scene, side by
// side in one run (the same voxelized sides, the same frames), with each mode's one-time setup and
// the process's peak resident size. Prints a table for BENCHMARKS.md.
//
//   volmorph_bench_variational [SCENE] [RESOLUTION] [RUNS] [TIMES]
//   (default: scenes/dino-to-eight-variational.toml at 256 voxels across, 3 runs of t = 0.25,
//   0.5, 0.75 per mode; TIMES a comma-separated list of t in their place)
#include <volmorph/Morph.h>
#include <volmorph/Scene.h>
#include <volmorph/SceneVolumes.h>

#include <openvdb/openvdb.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace volmorph;

namespace {

double seconds()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

double peakGiB()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / (1024.0 * 1024.0);
}

} // namespace

int main(int argc, char** argv)
{
    openvdb::initialize();
    const std::string file =
        argc > 1 ? argv[1]
                 : std::string(VOLMORPH_SOURCE_DIR) + "/scenes/dino-to-eight-variational.toml";
    const int resolution = argc > 2 ? std::atoi(argv[2]) : 256;
    const int runs = argc > 3 ? std::atoi(argv[3]) : 3;
    std::vector<double> times{0.25, 0.5, 0.75};
    if (argc > 4) {
        times.clear();
        for (const char* p = argv[4]; *p;) {
            char* end = nullptr;
            times.push_back(std::strtod(p, &end));
            if (end == p) break;
            p = *end == ',' ? end + 1 : end;
        }
    }
    Scene scene = loadScene(file);
    scene.volume.voxelSize.reset();
    scene.volume.resolution = resolution;
    BlendSpec sdf = scene.blend;
    sdf.mode = BlendMode::Sdf;
    BlendSpec variational = scene.blend;
    variational.mode = BlendMode::Variational;

    double start = seconds();
    const SceneVolumes v = voxelizeScene(scene);
    std::printf("%s at %d voxels across (voxel %g): voxelized in %.2f s\n", file.c_str(),
                resolution, v.source.voxelSize(), seconds() - start);
    MorphOptions options;
    options.secondsPerUnitT = 1.0; // with vel, as a render with motion blur makes them
    start = seconds();
    const Morpher bySdf(v.source, v.target, scene.pairs, scene.warp, sdf, options);
    const double sdfSetup = seconds() - start;
    options.influences = v.influences;
    start = seconds();
    const Morpher byVariational(v.source, v.target, scene.pairs, scene.warp, variational, options);
    const double variationalSetup = seconds() - start;
    std::printf("setup: sdf %.2f s, variational %.2f s (%d constraints per shape)\n", sdfSetup,
                variationalSetup, variational.variational.constraints);

    std::printf(
        "| t | sdf frame (s) | variational frame (s) | ratio | variational exact values |\n");
    std::printf("|---:|---:|---:|---:|---:|\n");
    std::vector<double> ratios;
    for (double t : times) {
        std::vector<double> a, b;
        MorphStats stats;
        for (int run = 0; run < runs; ++run) {
            start = seconds();
            bySdf.frame(t);
            a.push_back(seconds() - start);
            start = seconds();
            byVariational.frame(t, &stats);
            b.push_back(seconds() - start);
        }
        ratios.push_back(median(b) / median(a));
        std::printf("| %.2f | %.3f | %.3f | %.1f | %llu |\n", t, median(a), median(b),
                    ratios.back(), (unsigned long long)stats.blendSamples);
    }
    std::printf("medians of %d runs; ratio median %.1f; peak resident %.2f GiB\n", runs,
                median(ratios), peakGiB());
    return 0;
}
