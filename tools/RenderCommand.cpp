// volmorph render-vdb IN.vdb -o OUT.exr: render any float grid (flags as OpenVDB's vdb_render).
// volmorph render SCENE [--frames SPEC] [-o PATTERN.exr]: the morph of each frame, rendered.
#include "Common.h"
#include "SceneRender.h"

#include <volmorph/Frames.h>
#include <volmorph/Morph.h>
#include <volmorph/Version.h>
#include <volmorph/Voxelize.h>
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

Vec3d vec3(const std::vector<double>& v) { return Vec3d(v[0], v[1], v[2]); }

struct RenderVdbArgs {
    std::string input, output, png, camera = "persp", grid, resolution = "640x360";
    std::vector<double> translate, lookat, up{0, 1, 0}, light{0.3, 0.7, 0.6}, emission;
    double fov = 40.0, frameWidth = 0.0, extinction = 40.0, albedo = 0.8, step = 0.5;
    int shadowCache = 2;
    int samples = 4, threads = 0;
    double memoryLimitGiB = 0.0;
    bool floatExr = false;
};

void parseResolution(const std::string& text, int& width, int& height)
{
    char x = 0;
    std::istringstream in(text);
    if (!(in >> width >> x >> height) || x != 'x' || width < 1 || height < 1 || width > 16384 || height > 16384 ||
        !in.eof())
        throw UserError(SourceLocation{"--res"}, "expected WIDTHxHEIGHT in pixels (e.g. 640x360), got \"" + text + "\"");
}

int runRenderVdb(const RenderVdbArgs& args)
{
    int width = 0, height = 0;
    parseResolution(args.resolution, width, height); // flags first: no work before a usage error
    checkFilmMemory(width, height, args.memoryLimitGiB);
    openvdb::initialize();
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr color;
    try {
        openvdb::io::File file(args.input);
        file.open();
        // Only the two grids used are read (a voxelized mesh also holds its sdf).
        std::string densityName, colorName;
        for (auto it = file.beginName(); it != file.endName(); ++it) {
            const openvdb::GridBase::Ptr g = file.readGridMetadata(it.gridName());
            if (colorName.empty() && g->getName() == "Cd" && g->isType<openvdb::Vec3SGrid>()) colorName = it.gridName();
            if (!densityName.empty()) continue;
            if (!args.grid.empty() ? g->getName() == args.grid : g->isType<openvdb::FloatGrid>()) {
                if (!g->isType<openvdb::FloatGrid>())
                    throw UserError(SourceLocation{args.input}, "grid \"" + args.grid + "\" is not a float grid");
                densityName = it.gridName();
            }
        }
        if (!densityName.empty()) density = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(densityName));
        if (!colorName.empty()) color = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid(colorName));
        file.close();
    } catch (const openvdb::Exception& e) {
        throw UserError(SourceLocation{args.input}, std::string("cannot read volume file (") + e.what() + ")");
    }
    if (!density)
        throw UserError(SourceLocation{args.input},
                        args.grid.empty() ? "no float grid to render" : "no grid named \"" + args.grid + "\"");
    // Default view: in front of the grid's active bounds, looking at their centre.
    openvdb::CoordBBox box = density->evalActiveVoxelBoundingBox();
    const Vec3d lo = density->indexToWorld(box.min().asVec3d()), hi = density->indexToWorld(box.max().asVec3d());
    const Vec3d centre = 0.5 * (lo + hi);
    const double extent = (hi - lo).length();
    const Vec3d lookat = args.lookat.empty() ? centre : vec3(args.lookat);
    const Vec3d eye = args.translate.empty() ? centre + Vec3d(0, 0, 1.6 * extent) : vec3(args.translate);
    const bool ortho = args.camera == "ortho";
    const render::Camera camera(ortho ? render::Camera::Projection::Orthographic : render::Camera::Projection::Perspective,
                                eye, lookat, vec3(args.up), args.fov, args.frameWidth > 0 ? args.frameWidth : extent,
                                width, height);
    render::Light light;
    light.direction = -vec3(args.light); // the flag points toward the light, as vdb_render's -light
    if (args.light.size() == 6) light.color = Vec3d(args.light[3], args.light[4], args.light[5]);
    render::Medium medium;
    medium.extinction = args.extinction;
    medium.albedo = args.albedo;
    if (!args.emission.empty()) medium.emission = vec3(args.emission);
    render::RenderSettings settings;
    settings.samples = args.samples;
    settings.stepVoxels = args.step;
    settings.shadowCacheVoxels = args.shadowCache;
    settings.threads = args.threads;
    const auto start = std::chrono::steady_clock::now();
    const render::Image image = render::renderVolume(*density, color.get(), camera, {light}, medium, settings);
    const double seconds = secondsSince(start);
    render::ExrOptions exr;
    exr.halfFloat = !args.floatExr;
    exr.samples = args.samples;
    exr.renderSeconds = seconds;
    exr.metadata["volmorph:source"] = args.input;
    try {
        render::writeExr(image, camera, args.output, exr);
        if (!args.png.empty()) render::writePng(image, args.png);
    } catch (const std::runtime_error& e) {
        throw UserError(SourceLocation{args.output}, std::string("cannot write image (") + e.what() + ")");
    }
    std::printf("rendered %s (%dx%d, %d samples) in %.2f s -> %s\n", density->getName().c_str(), width, height,
                args.samples, seconds, args.output.c_str());
    return 0;
}

struct RenderSceneArgs {
    std::string scene, frames, output, png;
    int threads = 0;
    bool skipExisting = false, quiet = false;
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

int runRenderScene(const RenderSceneArgs& args)
{
    const Scene scene = loadScene(args.scene);
    const std::vector<int> frames = selectFrames(scene.frames, args.frames);
    const std::string pattern = args.output.empty() ? (scene.folder / scene.frames.output).string() : args.output;
    if (const std::string why = checkFramePattern(pattern); !why.empty())
        throw UserError(SourceLocation{"-o"}, "\"" + pattern + "\": " + why);

    Interrupter interrupter(false);
    StopSignals signals(interrupter);
    checkFilmMemory(scene.render.width, scene.render.height, args.memoryLimitGiB);
    const uint64_t memoryLimit = uint64_t(args.memoryLimitGiB * double(1ull << 30));
    SceneVolumes volumes = loadSceneVolumes(scene, args.cache, interrupter, memoryLimit, args.quiet);
    MorphOptions morphOptions;
    morphOptions.memoryLimitBytes = memoryLimit;
    const Morpher morpher(std::move(volumes.source), std::move(volumes.target), scene.pairs, scene.warp, scene.blend,
                          morphOptions);

    const SceneRender renderer(scene, args.threads);

    int failed = 0;
    // Two steps per frame (morph, render), so the progress moves within long frames too.
    Progress progress(2 * int(frames.size()), args.quiet);
    progress.update(0);
    for (size_t i = 0; i < frames.size(); ++i) {
        const int frame = frames[i];
        const std::filesystem::path file = frameFileName(pattern, frame);
        if (args.skipExisting && completeImage(file)) {
            progress.log("frame " + std::to_string(frame) + ": " + file.string() + " exists, skipped");
            progress.update(2 * int(i + 1));
            continue;
        }
        const auto start = std::chrono::steady_clock::now();
        const VolumeSet v = morpher.frame(scene.frames.t(frame), nullptr, &interrupter);
        if (interrupter.stopRequested()) throw Interrupted();
        progress.update(2 * int(i) + 1);
        const render::Image image = renderer.renderFrame(v, frame);
        if (interrupter.stopRequested()) throw Interrupted();
        render::ExrOptions exr;
        exr.frame = frame;
        exr.samples = scene.render.samples;
        exr.renderSeconds = secondsSince(start);
        exr.metadata["volmorph:scene"] = std::filesystem::absolute(args.scene).string();
        exr.metadata["volmorph:t"] = fmt(scene.frames.t(frame));
        try {
            if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
            render::writeExr(image, renderer.camera(frame), file, exr);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s: cannot write frame %d (%s)\n", file.string().c_str(), frame, e.what());
            ++failed;
            progress.update(2 * int(i + 1));
            continue;
        }
        char line[512];
        std::snprintf(line, sizeof line, "frame %d (t=%.4f): %.2f s -> %s", frame, scene.frames.t(frame),
                      secondsSince(start), file.string().c_str());
        progress.log(line);
        progress.update(2 * int(i + 1));
    }
    if (failed) std::fprintf(stderr, "volmorph: %d of %zu frames failed\n", failed, frames.size());
    return failed ? kExitUserError : 0;
}

} // namespace

namespace {

render::Camera sceneCamera(const CameraSpec& c, const RenderSpec& r, int width)
{
    const int w = width > 0 ? width : r.width;
    const int h = width > 0 ? std::max(1, int(std::lround(double(r.height) * w / r.width))) : r.height;
    return render::Camera(c.projection == Projection::Orthographic ? render::Camera::Projection::Orthographic
                                                                   : render::Camera::Projection::Perspective,
                          c.eye, c.lookat, c.up, c.fovDegrees, c.orthoWidth, w, h);
}

} // namespace

SceneRender::SceneRender(const Scene& scene, int threads, int width) : mSpec(scene.render), mWidth(width)
{
    const RenderSpec& r = scene.render;
    medium.extinction = r.extinction;
    medium.albedo = r.albedo;
    medium.anisotropy = r.anisotropy;
    medium.emission = r.emission;
    settings.samples = r.samples;
    settings.stepVoxels = r.stepVoxels;
    settings.seed = r.seed;
    settings.threads = threads;
}

render::Camera SceneRender::camera(int frame) const { return sceneCamera(mSpec.camera.at(frame), mSpec, mWidth); }

std::vector<render::Light> SceneRender::lights(int frame) const
{
    std::vector<render::Light> lights;
    for (const LightSpec& spec : mSpec.lights) {
        const LightSpec l = spec.at(frame);
        render::Light light;
        light.type = l.type == LightType::Point ? render::Light::Type::Point : render::Light::Type::Directional;
        light.direction = l.direction;
        light.position = l.position;
        light.color = l.color;
        light.intensity = l.intensity;
        lights.push_back(light);
    }
    return lights;
}

render::Image SceneRender::renderFrame(const VolumeSet& volumes, int frame) const
{
    render::RenderSettings s = settings;
    s.frame = frame;
    return render::renderVolume(*volumes.density, volumes.color.get(), camera(frame), lights(frame), medium, s);
}

Command addRenderVdbCommand(CLI::App& app)
{
    auto a = std::make_shared<RenderVdbArgs>();
    CLI::App* sub = app.add_subcommand("render-vdb", "Render a float grid of a .vdb file to OpenEXR (like vdb_render)");
    sub->add_option("IN", a->input, "input .vdb")->required();
    sub->add_option("-o,--output", a->output, "output .exr")->required();
    sub->add_option("--png", a->png, "also write an sRGB PNG preview");
    sub->add_option("--camera", a->camera, "persp or ortho")->check(CLI::IsMember({"persp", "ortho"}));
    sub->add_option("--translate", a->translate, "camera position X,Y,Z (world units)")->delimiter(',')->expected(3);
    sub->add_option("--lookat", a->lookat, "point the camera looks at X,Y,Z")->delimiter(',')->expected(3);
    sub->add_option("--up", a->up, "camera up vector X,Y,Z")->delimiter(',')->expected(3);
    sub->add_option("--fov", a->fov, "horizontal field of view, degrees (perspective)")->check(CLI::Range(0.01, 179.0));
    sub->add_option("--frame", a->frameWidth, "orthographic frame width, world units")->check(CLI::PositiveNumber);
    sub->add_option("--res", a->resolution, "image size WIDTHxHEIGHT");
    sub->add_option("--extinction", a->extinction, "extinction per world unit at density 1")->check(CLI::NonNegativeNumber);
    sub->add_option("--albedo", a->albedo, "scattering albedo 0..1")->check(CLI::Range(0.0, 1.0));
    sub->add_option("--emission", a->emission, "emitted radiance per unit optical depth R,G,B (linear, >= 0)")
        ->delimiter(',')->expected(3)->check(CLI::NonNegativeNumber);
    sub->add_option("--light", a->light, "direction toward the light X,Y,Z[,R,G,B] (as vdb_render)")->delimiter(',')
        ->expected(3, 6);
    sub->add_option("--samples", a->samples, "samples per pixel")->check(CLI::Range(1, 65536));
    sub->add_option("--step", a->step, "longest step of the scattering integral, in voxels (optical depth is exact)")->check(CLI::Range(0.01, 8.0));
    sub->add_option("--shadow-cache", a->shadowCache, "shadow map (directional) or grid (point light) spacing, in voxels")
        ->check(CLI::Range(1, 16));
    sub->add_option("--threads", a->threads, "threads (0 = all cores)")->check(CLI::Range(0, 1024));
    sub->add_option("--grid", a->grid, "name of the float grid (default: the first)");
    sub->add_option("--memory-limit", a->memoryLimitGiB, "refuse a film above this, in GiB (default: half the machine's memory)")
        ->check(CLI::PositiveNumber);
    sub->add_flag("--float", a->floatExr, "float EXR instead of half");
    return {sub, [a] { return runRenderVdb(*a); }};
}

Command addRenderCommand(CLI::App& app)
{
    auto a = std::make_shared<RenderSceneArgs>();
    CLI::App* sub = app.add_subcommand("render", "Render the scene's morph to one OpenEXR per frame");
    sub->add_option("SCENE", a->scene, "scene file (TOML)")->required();
    sub->add_option("--frames", a->frames, "frames to render, e.g. 1-10, 1-100x2, 1,5,10-20 (default: all)");
    sub->add_option("-o,--output", a->output, "output pattern, e.g. out/f.####.exr (default: the scene's)");
    sub->add_option("--threads", a->threads, "threads (0 = all cores)")->check(CLI::Range(0, 1024));
    sub->add_flag("--skip-existing", a->skipExisting, "skip frames whose file exists and reads back whole");
    sub->add_option("--memory-limit", a->memoryLimitGiB,
                    "voxels, in-betweens and film above this estimate are refused, in GiB (default: half the "
                    "machine's memory)")
        ->check(CLI::PositiveNumber);
    addCacheOptions(sub, a->cache);
    sub->add_flag("-q,--quiet", a->quiet, "print nothing on success");
    return {sub, [a] { return runRenderScene(*a); }};
}

} // namespace volmorph::cli
