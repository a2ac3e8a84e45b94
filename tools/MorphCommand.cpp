// volmorph morph SCENE [--frames SPEC] [-o PATTERN.vdb]: one .vdb of the in-between per frame; in
// surface mode -o PATTERN.ply|.obj writes the surface stage's mesh of each frame.
#include "Common.h"
#include "FrameLoop.h"
#include "SceneMorph.h"

#include <volmorph/Export.h>
#include <volmorph/Frames.h>
#include <volmorph/Morph.h>
#include <volmorph/SceneSurface.h>
#include <volmorph/Voxelize.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>

namespace volmorph::cli {
namespace {

struct MorphArgs {
    std::string scene, frames, output, mesh, sampling = "trilinear", preset = "volmorph", side;
    bool exact = false, half = false, quiet = false, verbose = false;
    double memoryLimitGiB = 0.0;
    CacheArgs cache;
};

/// Writes one in-between as a .vdb at `file` (and its surface, with --mesh).
void writeFrame(const VolumeSet& v, const std::filesystem::path& file, const MorphArgs& args,
                const Scene& scene, int frame)
{
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    const GridNames names = args.preset == "houdini"   ? GridNames::Houdini
                            : args.preset == "blender" ? GridNames::Blender
                                                       : GridNames::Volmorph;
    writeVolumeSet(v, file, frameVdbOptions(scene, args.scene, frame, names, args.half));
    if (!args.mesh.empty()) {
        const std::filesystem::path meshFile = frameFileName(args.mesh, frame);
        if (meshFile.has_parent_path()) std::filesystem::create_directories(meshFile.parent_path());
        writeMesh(surfaceMesh(v), meshFile);
    }
}

bool isMeshPattern(const std::string& pattern)
{
    const std::string ext = std::filesystem::path(pattern).extension().string();
    return ext == ".ply" || ext == ".obj";
}

/// Surface mode's meshes, one per frame: every frame the same vertices and triangles, with the
/// exact vertex velocity (world units per second) in a PLY's vx vy vz.
void writeSurfaceFrames(const Scene& scene, const std::vector<int>& frames,
                        const std::string& pattern, const MorphArgs& args)
{
    if (!args.mesh.empty() || !args.side.empty() || args.exact)
        throw UserError(SourceLocation{!args.mesh.empty()   ? "--mesh"
                                       : !args.side.empty() ? "--side"
                                                            : "--exact"},
                        "blend.mode = \"surface\" makes meshes: -o out.####.ply writes them "
                        "(--mesh, --side and --exact are the volume modes')");
    Interrupter interrupter(false, args.verbose);
    StopSignals signals(interrupter);
    interrupter.start("surface correspondence");
    const SceneSurface surface(scene, &interrupter);
    interrupter.end();
    FrameLoop loop(scene, frames, 1, args.quiet, true, interrupter);
    loop.run([&](const FrameStep& step) {
        const SurfaceFrame f = surface.frame(step.frame);
        const std::filesystem::path file = frameFileName(pattern, step.frame);
        if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
        writeSurfaceFrame(f, file);
        return FrameResult{FrameResult::Outcome::Done,
                           std::to_string(f.points.size()) + " vertices, " +
                               std::to_string(f.triangles.size()) + " triangles",
                           file.string()};
    });
}

int runMorph(const MorphArgs& args)
{
    Scene scene = loadScene(args.scene);
    const std::vector<int> frames = selectFrames(scene.frames, args.frames, "--frames");
    const bool surface = scene.blend.mode == BlendMode::Surface;
    // Default: the scene's output pattern with .vdb for .exr (.ply in surface mode), relative to
    // the scene's folder.
    std::string pattern = args.output;
    if (pattern.empty())
        pattern = (scene.folder / std::filesystem::path(scene.frames.output)
                                      .replace_extension(surface ? ".ply" : ".vdb"))
                      .string();
    if (const std::string why = checkFramePattern(pattern); !why.empty())
        throw UserError(SourceLocation{"-o"}, "\"" + pattern + "\": " + why);
    if (frames.size() > 1 && frameFileName(pattern, frames[0]) == frameFileName(pattern, frames[1]))
        throw UserError(SourceLocation{"-o"},
                        "\"" + pattern + "\" has no frame number placeholder (#### or %04d)");
    if (!args.mesh.empty()) {
        if (const std::string why = checkFramePattern(args.mesh); !why.empty())
            throw UserError(SourceLocation{"--mesh"}, "\"" + args.mesh + "\": " + why);
        if (!isMeshPattern(args.mesh))
            throw UserError(SourceLocation{"--mesh"},
                            "expected a pattern ending in .ply or .obj, got \"" + args.mesh + "\"");
    }
    if (isMeshPattern(pattern)) {
        if (!surface)
            throw UserError(SourceLocation{"-o"},
                            "\"" + pattern +
                                "\": a mesh per frame is surface mode's output (blend.mode = "
                                "\"surface\"); for a volume mode's surface use -o out.####.vdb "
                                "--mesh out.####.ply");
        writeSurfaceFrames(scene, frames, pattern, args);
        return 0;
    }
    if (args.exact) scene.warp.toleranceVoxels = 0.0;
    if (!args.side.empty() && surface)
        throw UserError(SourceLocation{"--side"},
                        "blend.mode = \"surface\" warps neither side; --side shows how a side "
                        "bends under the warp, in density and sdf modes");
    if (!args.side.empty() && scene.blend.mode == BlendMode::Variational)
        throw UserError(SourceLocation{"--side"},
                        "blend.mode = \"variational\" warps neither side (its in-betweens are "
                        "slices of one function, the pairs are not used); --side shows how a side "
                        "bends under the warp, in density and sdf modes");
    if (!args.side.empty()) keepOneSide(scene.blend, args.side == "target");

    Interrupter interrupter(false, args.verbose);
    StopSignals signals(interrupter);
    MorphOptions options = morphCommandOptions(scene);
    if (args.sampling == "triquadratic") options.sampling = MorphOptions::Sampling::Triquadratic;
    options.memoryLimitBytes = memoryLimitBytes(args.memoryLimitGiB);
    SceneMorph morph(scene, args.cache, interrupter, options, args.quiet);

    FrameLoop loop(scene, frames, 1, args.quiet, true, interrupter);
    loop.run([&](const FrameStep& step) {
        MorphStats stats;
        const VolumeSet v = morph.frame(step.frame, &stats);
        const std::filesystem::path file = frameFileName(pattern, step.frame);
        writeFrame(v, file, args, scene, step.frame);
        char detail[160];
        std::snprintf(detail, sizeof detail, "%llu active voxels, warp error <= %.3f voxels",
                      (unsigned long long)stats.activeVoxels, stats.maxWarpErrorVoxels);
        return FrameResult{FrameResult::Outcome::Done, detail, file.string()};
    });
    return 0;
}

} // namespace

Command addMorphCommand(CLI::App& app)
{
    auto args = std::make_shared<MorphArgs>();
    CLI::App* sub = app.add_subcommand(
        "morph", "Write the morphed volume of each frame as a .vdb (grids density, Cd, vel)");
    sub->add_option("SCENE", args->scene, "scene file (TOML)")->required();
    sub->add_option("--frames", args->frames,
                    "frames to write, e.g. 1-10, 1-100x2, 1,5,10-20 (default: all)");
    sub->add_option(
        "-o,--output", args->output,
        "output pattern, e.g. out/morph.####.vdb; in surface mode also out/morph.####.ply or .obj, "
        "one mesh per frame (default: the scene's output with .vdb, .ply in surface mode)");
    sub->add_option(
        "--mesh", args->mesh,
        "also write each in-between's surface, e.g. out/morph.####.ply (PLY with colours, or OBJ)");
    sub->add_flag("--exact", args->exact, "use the exact warp everywhere (the reference; slow)");
    sub->add_option("--sampling", args->sampling, "resampling filter: trilinear or triquadratic")
        ->check(CLI::IsMember({"trilinear", "triquadratic"}));
    sub->add_option(
           "--memory-limit", args->memoryLimitGiB,
           "voxelization and in-between memory limit in GiB (default: half the machine's memory)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--preset", args->preset,
                    "grid names: volmorph (sdf, density, Cd), houdini (surface, density, Cd, "
                    "vel) or blender (sdf, density, color, velocity); carried grids keep theirs")
        ->check(CLI::IsMember({"volmorph", "houdini", "blender"}));
    sub->add_flag("--half", args->half, "store float and vec3 grids as 16-bit floats");
    sub->add_option("--side", args->side,
                    "write one side alone, warped at each frame's t: source or target (how each "
                    "side bends; every schedule held at 0 or 1; density and sdf modes)")
        ->check(CLI::IsMember({"source", "target"}));
    addCacheOptions(sub, args->cache);
    sub->add_flag("-q,--quiet", args->quiet, "print nothing on success");
    sub->add_flag("-v,--verbose", args->verbose,
                  "print each stage as it starts, with the time since the start (stderr)");
    return {sub, [args] { return runMorph(*args); }};
}

} // namespace volmorph::cli
