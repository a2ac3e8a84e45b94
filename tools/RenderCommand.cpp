// volmorph render-vdb IN.vdb -o OUT.exr: render any float grid (flags as OpenVDB's vdb_render).
// volmorph render SCENE [--frames SPEC] [-o PATTERN.exr]: the morph of each frame, rendered.
#include "Common.h"
#include "FrameLoop.h"
#include "NoiseTarget.h"
#include "SceneMorph.h"
#include "SceneRender.h"

#include <volmorph/Frames.h>
#include <volmorph/Morph.h>
#include <volmorph/core/VdbRead.h>
#include <volmorph/core/Version.h>
#include <volmorph/Voxelize.h>
#include <volmorph/render/EnvironmentMap.h>
#include <volmorph/render/Output.h>
#include <volmorph/render/Renderer.h>

#include <openvdb/io/File.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>

namespace volmorph::cli {
namespace {

Vec3d vec3(const std::vector<double>& v)
{
    return Vec3d(v[0], v[1], v[2]);
}

/// The flags vdb_render also has take its defaults: a 1920x1080 image, one sample per pixel
/// through its centre, a field of view of 2 atan(41.2136 / (2 x 50)) = 44.8 degrees (its 41.2 mm
/// aperture and 50 mm focal length), a step of 1 voxel, and its light (toward 0.3,0.3,0, colour
/// 0.7). The camera is placed to frame the volume unless --translate places it (vdb_render's
/// default, the origin, is inside most volumes).
struct RenderVdbArgs {
    std::string input, output, png, camera = "persp", grid, resolution = "1920x1080", envMap;
    std::vector<double> translate, lookat, up{0, 1, 0}, light, emission, env,
        propColor{0.8, 0.8, 0.8};
    std::vector<std::string> props; ///< meshes in world units, diffuse, coloured propColor
    double fov = 2.0 * std::atan(41.2136 / 100.0) * 180.0 / M_PI, frameWidth = 0.0,
           extinction = 40.0, albedo = 0.8, step = 1.0, lightAngle = 0.0;
    int shadowCache = 1;
    int samples = 1, threads = 0, bounces = 0;
    unsigned seed = 0;
    double memoryLimitGiB = 0.0, noise = 0.0;
    std::vector<double> shutter; ///< open, close in frames: motion blur along the vel grid
    double fps = 24.0;
    bool floatExr = false, noLayers = false, verbose = false, noDenoise = false;
};

void parseResolution(const std::string& text, int& width, int& height)
{
    char x = 0;
    std::istringstream in(text);
    if (!(in >> width >> x >> height) || x != 'x' || width < 1 || height < 1 || width > 16384 ||
        height > 16384 || !in.eof())
        throw UserError(SourceLocation{"--res"},
                        "expected WIDTHxHEIGHT in pixels (e.g. 640x360), got \"" + text + "\"");
}

struct InputGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr color;
    openvdb::Vec3SGrid::Ptr velocity; ///< `vel` or Blender's `velocity`, world units per second
};

/// The float grid to render (--grid, or the first) and the `Cd` colour grid if there is one; only
/// those two are read (a voxelized mesh also holds its sdf).
InputGrids readInputGrids(const RenderVdbArgs& args)
{
    openvdb::initialize();
    InputGrids grids;
    openvdb::GridPtrVecPtr all;
    try {
        all = readVdbGrids(args.input);
    } catch (const std::exception& e) {
        throw UserError(SourceLocation{args.input},
                        std::string("cannot read volume file (") + e.what() + ")");
    }
    for (const openvdb::GridBase::Ptr& g : *all) {
        if (!grids.color && g->getName() == "Cd")
            grids.color = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g);
        if (!grids.velocity && (g->getName() == "vel" || g->getName() == "velocity"))
            grids.velocity = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g);
        if (grids.density) continue;
        if (!args.grid.empty() ? g->getName() == args.grid : g->isType<openvdb::FloatGrid>()) {
            grids.density = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
            if (!grids.density)
                throw UserError(SourceLocation{args.input},
                                "grid \"" + args.grid + "\" is not a float grid");
        }
    }
    if (!grids.density)
        throw UserError(SourceLocation{args.input}, args.grid.empty()
                                                        ? "no float grid to render"
                                                        : "no grid named \"" + args.grid + "\"");
    return grids;
}

/// The flags' camera; by default in front of the grid's active bounds, looking at their centre.
render::Camera vdbCamera(const RenderVdbArgs& args, const openvdb::FloatGrid& density, int width,
                         int height)
{
    openvdb::CoordBBox box = density.evalActiveVoxelBoundingBox();
    const Vec3d lo = density.indexToWorld(box.min().asVec3d()),
                hi = density.indexToWorld(box.max().asVec3d());
    const Vec3d centre = 0.5 * (lo + hi);
    const double extent = (hi - lo).length();
    const Vec3d lookat = args.lookat.empty() ? centre : vec3(args.lookat);
    const Vec3d eye =
        args.translate.empty() ? centre + Vec3d(0, 0, 1.6 * extent) : vec3(args.translate);
    const bool ortho = args.camera == "ortho";
    return render::Camera(ortho ? render::Camera::Projection::Orthographic
                                : render::Camera::Projection::Perspective,
                          eye, lookat, vec3(args.up), args.fov,
                          args.frameWidth > 0 ? args.frameWidth : extent, width, height);
}

/// The flags' lights: --light (a directional light; by default vdb_render's, toward 0.3,0.3,0 with
/// colour 0.7) unless --env or --env-map alone is given, and the environment of --env (a constant
/// sky) or --env-map (a lat-long map, times --env when given).
std::vector<render::Light> vdbLights(const RenderVdbArgs& args)
{
    std::vector<render::Light> lights;
    const bool sky = !args.env.empty() || !args.envMap.empty();
    if (!args.light.empty() || !sky) {
        const std::vector<double> toward =
            args.light.empty() ? std::vector<double>{0.3, 0.3, 0.0, 0.7, 0.7, 0.7} : args.light;
        render::Light light;
        light.direction = -vec3(toward); // the flag points toward the light, as vdb_render's
        if (toward.size() == 6) light.color = Vec3d(toward[3], toward[4], toward[5]);
        light.angle = args.lightAngle * M_PI / 180.0; // degrees on the command line
        lights.push_back(light);
    }
    if (sky) {
        render::Light environment;
        environment.type = render::Light::Type::Environment;
        if (!args.env.empty()) environment.color = vec3(args.env);
        if (!args.envMap.empty()) {
            try {
                environment.map = render::EnvironmentMap::read(args.envMap);
            } catch (const std::exception& e) {
                throw UserError(SourceLocation{args.envMap},
                                std::string("cannot read the sky map (") + e.what() + ")");
            }
        }
        lights.push_back(environment);
    }
    return lights;
}

/// The --prop meshes, diffuse, coloured --prop-color; UserError naming a mesh that cannot be read.
std::shared_ptr<const render::Props> vdbProps(const RenderVdbArgs& args)
{
    std::vector<PropSpec> specs;
    for (const std::string& mesh : args.props) {
        PropSpec spec;
        spec.mesh = mesh;
        spec.where = SourceLocation{mesh};
        spec.color = vec3(args.propColor);
        specs.push_back(spec);
    }
    return importProps(specs);
}

/// The still image, or with --shutter the image blurred along the file's velocity grid.
render::Image renderVdbImage(const RenderVdbArgs& args, const InputGrids& grids,
                             const render::Camera& camera, const std::vector<render::Light>& lights,
                             const render::Medium& medium, render::RenderSettings settings)
{
    if (args.shutter.empty() || !(args.shutter[1] > args.shutter[0]))
        return render::renderVolume(*grids.density, grids.color.get(), camera, lights, medium,
                                    settings);
    if (!grids.velocity)
        throw UserError(SourceLocation{args.input},
                        "--shutter needs a vec3 velocity grid named vel (or velocity); the file "
                        "has none");
    std::vector<render::ShutterTime> times;
    for (double offset : render::shutterOffsets(args.shutter[0], args.shutter[1], args.samples))
        times.push_back({offset / args.fps, camera, lights});
    settings.centreSingleSample = false;
    return render::renderMotionBlurred(*grids.density, grids.color.get(), grids.velocity.get(),
                                       times, medium, settings);
}

int runRenderVdb(const RenderVdbArgs& args)
{
    int width = 0, height = 0;
    parseResolution(args.resolution, width, height); // flags first: no work before a usage error
    if (!args.shutter.empty() && !(args.shutter[0] <= args.shutter[1]))
        throw UserError(SourceLocation{"--shutter"},
                        "expected OPEN,CLOSE in frames with OPEN <= CLOSE, got " +
                            std::to_string(args.shutter[0]) + "," +
                            std::to_string(args.shutter[1]));
    checkFilmMemory(width, height, args.memoryLimitGiB, !args.noLayers);
    Interrupter interrupter(false, args.verbose);
    StopSignals signals(interrupter);
    // The sky map and the props before the volume: no work before an error in them.
    const std::vector<render::Light> lights = vdbLights(args);
    const std::shared_ptr<const render::Props> props = vdbProps(args);
    const InputGrids grids = readInputGrids(args);
    const render::Camera camera = vdbCamera(args, *grids.density, width, height);
    render::Medium medium;
    medium.extinction = args.extinction;
    medium.albedo = args.albedo;
    if (!args.emission.empty()) medium.emission = vec3(args.emission);
    render::RenderSettings settings;
    settings.samples = args.samples;
    settings.noise = args.noise;
    settings.seed = args.seed;
    settings.denoise = !args.noDenoise;
    settings.stepVoxels = args.step;
    settings.shadowCacheVoxels = args.shadowCache;
    settings.bounces = args.bounces;
    settings.layers = !args.noLayers;
    settings.threads = args.threads;
    settings.interrupter = &interrupter;
    settings.props = props.get();
    const auto start = std::chrono::steady_clock::now();
    const render::Image image = renderVdbImage(args, grids, camera, lights, medium, settings);
    const double seconds = secondsSince(start);
    render::ExrOptions exr;
    exr.halfFloat = !args.floatExr;
    exr.samples = args.samples;
    exr.noiseTarget = args.noise;
    exr.renderSeconds = seconds;
    exr.metadata["volmorph:source"] = args.input;
    try {
        render::writeExr(image, camera, args.output, exr);
        if (!args.png.empty()) render::writePng(image, args.png);
    } catch (const std::runtime_error& e) {
        throw UserError(SourceLocation{args.output},
                        std::string("cannot write image (") + e.what() + ")");
    }
    std::printf("rendered %s (%dx%d, %s) in %.2f s -> %s\n", grids.density->getName().c_str(),
                width, height, samplesAndNoise(image, args.samples, args.noise).c_str(), seconds,
                args.output.c_str());
    return 0;
}

struct RenderSceneArgs {
    std::string scene, frames, output, png;
    int threads = 0;
    double noise = -1.0; ///< --noise: the scene's render.noise overridden (negative: not given)
    bool skipExisting = false, quiet = false, verbose = false;
    double memoryLimitGiB = 0.0;
    CacheArgs cache;
};

/// True when `path` exists and reads back whole.
bool completeImage(const std::filesystem::path& path)
{
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return false;
    try {
        render::readImage(path);
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

/// Writes frame `frame`'s image, or returns why it could not.
std::string writeFrameImage(const render::Image& image, const SceneRender& renderer,
                            const std::filesystem::path& file, const RenderSceneArgs& args,
                            const Scene& scene, const FrameStep& step, double seconds)
{
    try {
        writeFrameExr(image, renderer, scene, args.scene, step.frame, file, seconds);
    } catch (const std::exception& e) {
        return file.string() + ": cannot write frame " + std::to_string(step.frame) + " (" +
               e.what() + ")";
    }
    return "";
}

int runRenderScene(const RenderSceneArgs& args)
{
    const Scene scene = loadScene(args.scene);
    const std::vector<int> frames = selectFrames(scene.frames, args.frames, "--frames");
    const std::string pattern =
        args.output.empty() ? (scene.folder / scene.frames.output).string() : args.output;
    if (const std::string why = checkFramePattern(pattern); !why.empty())
        throw UserError(SourceLocation{"-o"}, "\"" + pattern + "\": " + why);

    Interrupter interrupter(false, args.verbose);
    StopSignals signals(interrupter);
    checkFilmMemory(scene.render.width, scene.render.height, args.memoryLimitGiB,
                    scene.render.layers);
    SceneRender renderer(scene, args.threads);
    if (args.noise >= 0.0) renderer.settings.noise = args.noise;
    MorphOptions morphOptions = renderMorphOptions(scene, renderer);
    morphOptions.memoryLimitBytes = memoryLimitBytes(args.memoryLimitGiB);
    SceneMorph morph(scene, args.cache, interrupter, morphOptions, args.quiet);
    renderer.settings.interrupter = &interrupter;

    // Two steps per frame (morph, render), so the progress moves within long frames too.
    FrameLoop loop(scene, frames, 2, args.quiet, true, interrupter);
    const int failed = loop.run([&](const FrameStep& step) {
        const std::filesystem::path file = frameFileName(pattern, step.frame);
        if (args.skipExisting && completeImage(file))
            return FrameResult{FrameResult::Outcome::Skipped,
                               "frame " + std::to_string(step.frame) + ": " + file.string() +
                                   " exists, skipped",
                               ""};
        const auto start = std::chrono::steady_clock::now();
        const render::Image image =
            renderMorphFrame(renderer, morph, step.frame, [&] { step.progress(1); });
        const std::string error =
            writeFrameImage(image, renderer, file, args, scene, step, secondsSince(start));
        if (!error.empty()) return FrameResult{FrameResult::Outcome::Failed, error, ""};
        return FrameResult{FrameResult::Outcome::Done,
                           samplesAndNoise(image, scene.render.samples, renderer.settings.noise),
                           file.string()};
    });
    return failed ? kExitUserError : 0;
}

/// render-vdb's lights and props: --light, --env, --light-angle, --prop, --prop-color, --env-map.
void addShotOptions(CLI::App* sub, RenderVdbArgs& a)
{
    sub->add_option("--light", a.light,
                    "direction toward the light X,Y,Z[,R,G,B] (as vdb_render; default "
                    "0.3,0.3,0,0.7,0.7,0.7 unless --env alone)")
        ->delimiter(',')
        ->expected(3, 6);
    sub->add_option("--env", a.env,
                    "environment light: radiance R,G,B from every direction (alone: no --light "
                    "unless given)")
        ->delimiter(',')
        ->expected(3)
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--light-angle", a.lightAngle,
                    "the --light's angular diameter in degrees (a soft sun; 0: a point)")
        ->check(CLI::Range(0.0, 180.0));
    sub->add_option("--prop", a.props,
                    "a mesh in the shot (world units, as the volume's), diffuse: it occludes the "
                    "volume, casts and receives shadows (repeat for more)");
    sub->add_option("--prop-color", a.propColor, "the props' reflectance R,G,B (default 0.8)")
        ->delimiter(',')
        ->expected(3)
        ->check(CLI::Range(0.0, 1.0));
    sub->add_option("--env-map", a.envMap,
                    "environment light from a lat-long HDR image (EXR, HDR, ...; its centre looks "
                    "along +x, y up), importance-sampled; times --env R,G,B when given (alone: no "
                    "--light unless given)");
}

} // namespace

Command addRenderVdbCommand(CLI::App& app)
{
    auto a = std::make_shared<RenderVdbArgs>();
    CLI::App* sub = app.add_subcommand(
        "render-vdb", "Render a float grid of a .vdb file to OpenEXR (like vdb_render)");
    sub->add_option("IN", a->input, "input .vdb")->required();
    sub->add_option("-o,--output", a->output, "output .exr")->required();
    sub->add_option("--png", a->png, "also write an sRGB PNG preview");
    sub->add_option("--camera", a->camera, "persp or ortho")
        ->check(CLI::IsMember({"persp", "ortho"}));
    sub->add_option(
           "--translate", a->translate,
           "camera position X,Y,Z (world units; default: in front of the volume, framing it)")
        ->delimiter(',')
        ->expected(3);
    sub->add_option("--lookat", a->lookat,
                    "point the camera looks at X,Y,Z (default: the volume's centre)")
        ->delimiter(',')
        ->expected(3);
    sub->add_option("--up", a->up, "camera up vector X,Y,Z")->delimiter(',')->expected(3);
    sub->add_option("--fov", a->fov, "horizontal field of view, degrees (perspective)")
        ->check(CLI::Range(0.01, 179.0));
    sub->add_option("--frame", a->frameWidth,
                    "orthographic frame width, world units (default: the volume's extent)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--res", a->resolution, "image size WIDTHxHEIGHT");
    sub->add_option("--extinction", a->extinction, "extinction per world unit at density 1")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--albedo", a->albedo, "scattering albedo 0..1")->check(CLI::Range(0.0, 1.0));
    sub->add_option("--emission", a->emission,
                    "emitted radiance per unit optical depth R,G,B (linear, >= 0)")
        ->delimiter(',')
        ->expected(3)
        ->check(CLI::NonNegativeNumber);
    addShotOptions(sub, *a);
    sub->add_option("--bounces", a->bounces,
                    "volume scattering events after the first (0: single scattering; more: "
                    "path tracing)")
        ->check(CLI::Range(0, 100000));
    sub->add_option("--samples", a->samples, "samples per pixel (the cap under a noise target)")
        ->check(CLI::Range(1, 65536));
    addNoiseOption(sub, a->noise);
    sub->add_flag("--no-denoise", a->noDenoise,
                  "under a noise target, reach it by samples alone (no denoiser: no bias)");
    sub->add_option("--seed", a->seed,
                    "the samples' seed (another seed: another, independent, image of the same "
                    "noise)");
    sub->add_option("--shutter", a->shutter,
                    "motion blur along the vel grid: the shutter's OPEN,CLOSE in frames around "
                    "the frame (e.g. -0.25,0.25); one shutter time per sample, up to 64")
        ->delimiter(',')
        ->expected(2);
    sub->add_option("--fps", a->fps, "frames per second, for --shutter (default 24)")
        ->check(CLI::PositiveNumber);
    sub->add_option("--step", a->step,
                    "longest step of the scattering integral, in voxels (optical depth is exact)")
        ->check(CLI::Range(0.01, 8.0));
    sub->add_option("--shadow-cache", a->shadowCache,
                    "single scattering's shadow maps' spacing (directional and point lights), in "
                    "voxels (0: exact transmittance per sample, slow: the reference); traced paths "
                    "use ratio tracking")
        ->check(CLI::Range(0, 16));
    sub->add_option("--threads", a->threads, "threads (0 = all cores)")->check(CLI::Range(0, 1024));
    sub->add_option("--grid", a->grid, "name of the float grid (default: the first)");
    sub->add_option("--memory-limit", a->memoryLimitGiB,
                    "refuse a film above this, in GiB (default: half the machine's memory)")
        ->check(CLI::PositiveNumber);
    sub->add_flag("--float", a->floatExr, "float EXR instead of half");
    sub->add_flag("--no-layers", a->noLayers,
                  "RGBA alone, without the layers for compositing (volume, direct, indirect, "
                  "emission, shadow, depth.Z)");
    sub->add_flag("-v,--verbose", a->verbose,
                  "print each stage as it starts, with the time since the start (stderr)");
    return {sub, [a] { return runRenderVdb(*a); }};
}

Command addRenderCommand(CLI::App& app)
{
    auto a = std::make_shared<RenderSceneArgs>();
    CLI::App* sub =
        app.add_subcommand("render", "Render the scene's morph to one OpenEXR per frame");
    sub->add_option("SCENE", a->scene, "scene file (TOML)")->required();
    sub->add_option("--frames", a->frames,
                    "frames to render, e.g. 1-10, 1-100x2, 1,5,10-20 (default: all)");
    sub->add_option("-o,--output", a->output,
                    "output pattern, e.g. out/f.####.exr (default: the scene's)");
    sub->add_option("--threads", a->threads, "threads (0 = all cores)")->check(CLI::Range(0, 1024));
    addNoiseOption(sub, a->noise);
    sub->add_flag("--skip-existing", a->skipExisting,
                  "skip frames whose file exists and reads back whole");
    sub->add_option("--memory-limit", a->memoryLimitGiB,
                    "voxels, in-betweens and film above this estimate are refused, in GiB "
                    "(default: half the "
                    "machine's memory)")
        ->check(CLI::PositiveNumber);
    addCacheOptions(sub, a->cache);
    sub->add_flag("-q,--quiet", a->quiet, "print nothing on success");
    sub->add_flag("-v,--verbose", a->verbose,
                  "print each stage as it starts, with the time since the start (stderr)");
    return {sub, [a] { return runRenderScene(*a); }};
}

} // namespace volmorph::cli
