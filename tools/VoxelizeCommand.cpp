// volmorph voxelize MESH -o OUT.vdb: sdf, density and Cd grids of one mesh.
#include "Common.h"

#include <volmorph/core/Version.h>
#include <volmorph/Voxelize.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>

namespace volmorph::cli {
namespace {

struct VoxelizeArgs {
    std::string mesh, output, sign = "auto";
    std::optional<double> voxelSize;
    std::optional<int> resolution;
    float halfWidth = 3.0f;
    std::vector<float> color;
    double memoryLimitGiB = 0.0;
    bool quiet = false;
};

/// How the inside was decided, for the log and the file's metadata.
const char* signName(VoxelizeStats::SignPath path)
{
    switch (path) {
    case VoxelizeStats::SignPath::FloodFill:
        return "flood fill (watertight, one shell)";
    case VoxelizeStats::SignPath::ClosedShells:
        return "closed shells (winding-number rule)";
    case VoxelizeStats::SignPath::WindingNumber:
        return "winding number";
    }
    return "";
}

int runVoxelize(const VoxelizeArgs& args)
{
    // Signals are caught from the start: one arriving while the mesh is read (Assimp cannot be
    // asked to stop) ends the command right after it, with status 130 like any other.
    Interrupter interrupter(!args.quiet && isatty(fileno(stderr)));
    StopSignals signals(interrupter);
    const Mesh mesh = importMesh(args.mesh);
    if (interrupter.stopRequested()) throw Interrupted();
    VoxelizeOptions options;
    options.voxelSize = args.voxelSize;
    if (args.resolution) options.resolution = *args.resolution;
    options.halfWidthVoxels = args.halfWidth;
    if (!args.color.empty()) options.color = Vec3f(args.color[0], args.color[1], args.color[2]);
    options.memoryLimitBytes = memoryLimitBytes(args.memoryLimitGiB);
    options.sign = args.sign == "winding"     ? VoxelizeOptions::Sign::WindingNumber
                   : args.sign == "floodfill" ? VoxelizeOptions::Sign::FloodFill
                                              : VoxelizeOptions::Sign::Auto;
    const std::filesystem::path output(args.output);
    const std::filesystem::path folder = output.has_parent_path() ? output.parent_path() : ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
        throw UserError(SourceLocation{args.output}, "the output folder does not exist");

    VoxelizeStats stats;
    const auto start = std::chrono::steady_clock::now();
    const VolumeSet volumes = voxelize(mesh, options, &interrupter, &stats);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (interrupter.stopRequested()) throw Interrupted();
    std::ostringstream voxel;
    voxel << stats.voxelSize;
    VdbWriteOptions write;
    write.metadata = {{"volmorph_source", std::filesystem::absolute(args.mesh).string()},
                      {"volmorph_voxel_size", voxel.str()},
                      {"volmorph_sign", signName(stats.signPath)},
                      {"volmorph_version", versionString()}};
    writeVolumeSet(volumes, output, write);
    if (!args.quiet) {
        std::printf("%s: %zu triangles, %s\n", args.mesh.c_str(), mesh.triangles.size(),
                    describeTopology(mesh.report).c_str());
        std::printf("voxel size %s world units; inside/outside by %s", voxel.str().c_str(),
                    signName(stats.signPath));
        if (stats.holesFilled) std::printf(", %zu holes filled", stats.holesFilled);
        std::printf("\n");
        std::printf("sdf %llu active voxels, density %llu active voxels, %.2f s\n",
                    (unsigned long long)stats.sdfActiveVoxels,
                    (unsigned long long)stats.densityActiveVoxels, seconds);
        std::printf("wrote %s (grids sdf, density, Cd)\n", args.output.c_str());
    }
    return 0;
}

struct CacheCommandArgs {
    std::string scene;
    CacheArgs cache;
    double memoryLimitGiB = 0.0;
    bool quiet = false;
};

int runCache(const CacheCommandArgs& args)
{
    const Scene scene = loadScene(args.scene);
    if (args.cache.resolve().empty())
        throw UserError(SourceLocation{"--cache"},
                        "no cache folder: give --cache DIR or set VOLMORPH_CACHE");
    Interrupter interrupter(false);
    StopSignals signals(interrupter);
    loadSceneVolumes(scene, args.cache, interrupter, memoryLimitBytes(args.memoryLimitGiB),
                     args.quiet);
    return 0;
}

} // namespace

Command addCacheCommand(CLI::App& app)
{
    auto a = std::make_shared<CacheCommandArgs>();
    CLI::App* sub = app.add_subcommand("cache", "Voxelize a scene's source and target into the "
                                                "voxel cache (once, before a farm job's chunks)");
    sub->add_option("SCENE", a->scene, "scene file (TOML)")->required();
    sub->add_option("--cache", a->cache.folder,
                    "voxel cache folder (default: $VOLMORPH_CACHE, else $XDG_CACHE_HOME/volmorph, "
                    "else ~/.cache/volmorph)");
    sub->add_option("--memory-limit", a->memoryLimitGiB, "voxelization memory limit in GiB")
        ->check(CLI::PositiveNumber);
    sub->add_flag("-q,--quiet", a->quiet, "print nothing on success");
    return {sub, [a] { return runCache(*a); }};
}

Command addVoxelizeCommand(CLI::App& app)
{
    auto vox = std::make_shared<VoxelizeArgs>();
    CLI::App* voxelizeCmd =
        app.add_subcommand("voxelize", "Voxelize a mesh into sdf, density and Cd grids");
    voxelizeCmd->add_option("MESH", vox->mesh, "mesh file (OBJ, PLY, STL, OFF, glTF, ...)")
        ->required();
    voxelizeCmd->add_option("-o,--output", vox->output, "output .vdb file")->required();
    auto* sizeOpt =
        voxelizeCmd->add_option("--voxel-size", vox->voxelSize, "voxel edge in world units")
            ->check(CLI::PositiveNumber);
    voxelizeCmd
        ->add_option("--resolution", vox->resolution,
                     "voxels across the longest side (default 128)")
        ->check(CLI::Range(8, 16384))
        ->excludes(sizeOpt);
    voxelizeCmd
        ->add_option("--half-width", vox->halfWidth, "narrow band half width in voxels (>= 3)")
        ->check(CLI::Range(3.0f, 64.0f));
    voxelizeCmd->add_option("--color", vox->color, "constant linear RGB colour R,G,B")
        ->delimiter(',')
        ->expected(3);
    voxelizeCmd
        ->add_option("--memory-limit", vox->memoryLimitGiB,
                     "refuse above this estimate, in GiB (default: half the machine's memory)")
        ->check(CLI::PositiveNumber);
    voxelizeCmd->add_option("--sign", vox->sign, "inside/outside: auto, floodfill or winding")
        ->check(CLI::IsMember({"auto", "floodfill", "winding"}));
    voxelizeCmd->add_flag("-q,--quiet", vox->quiet, "print nothing on success");
    return {voxelizeCmd, [vox] { return runVoxelize(*vox); }};
}

} // namespace volmorph::cli
