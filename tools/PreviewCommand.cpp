// volmorph preview SCENE --frame N -o OUT.png: one frame with every feature pair drawn on it, for
// editing the pairs by hand; --contact-sheet: a grid of frames.
#include "Common.h"
#include "FrameLoop.h"
#include "SceneMorph.h"
#include "SceneRender.h"

#include <volmorph/Feature.h>
#include <volmorph/Frames.h>
#include <volmorph/LocalTime.h>
#include <volmorph/Mesh.h>
#include <volmorph/VolumeInput.h>
#include <volmorph/Morph.h>
#include <volmorph/render/Output.h>
#include <volmorph/render/Overlay.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

namespace volmorph::cli {
namespace {

// Linear RGB. The interpolated element (the one the warp uses at t) is the brightest.
constexpr render::Color kInterpolated{1.0f, 0.75f, 0.05f};
constexpr render::Color kSourceSide{0.05f, 0.6f, 1.0f};
constexpr render::Color kTargetSide{1.0f, 0.1f, 0.6f};
constexpr render::Color kBackground{0.02f, 0.02f, 0.025f};
// [timing]: where places start now (green), where they finish now (white), regions (violet).
constexpr render::Color kStarting{0.1f, 0.9f, 0.2f};
constexpr render::Color kFinishing{0.9f, 0.9f, 0.9f};
constexpr render::Color kRegion{0.6f, 0.3f, 1.0f};

struct PreviewArgs {
    std::string scene, output, frames, from;
    std::optional<int> frame;
    bool contactSheet = false, sides = false, noFeatures = false, features = false, quiet = false,
         verbose = false;
    int width = 0, columns = 6, tileWidth = 240, threads = 0;
    std::optional<int> samples;
    CacheArgs cache;
};

void drawElement(render::Image& image, const render::Camera& camera, const Feature& f,
                 const render::Color& color)
{
    for (const auto& [a, b] : f.outline()) render::drawSegment(image, camera, a, b, color);
    render::drawMarker(image, camera, f.origin, color, f.type == FeatureType::Point ? 5 : 2);
}

/// Draws every pair at time t: the interpolated element with its number, and optionally the
/// source-side and target-side elements. Returns false when the labels could not be drawn.
bool drawFeatures(render::Image& image, const render::Camera& camera, const Scene& scene, double t,
                  bool sides)
{
    bool labels = true;
    for (size_t i = 0; i < scene.pairs.size(); ++i) {
        const FeaturePairSpec& p = scene.pairs[i];
        const Feature source = Feature::fromElement(p.source, p.type);
        const Feature target = Feature::fromElement(p.target, p.type);
        if (sides) {
            drawElement(image, camera, source, kSourceSide);
            drawElement(image, camera, target, kTargetSide);
        }
        const Feature now = interpolate(source, target, t);
        drawElement(image, camera, now, kInterpolated);
        if (const auto q = render::project(camera, now.origin); q && labels)
            labels = render::drawText(image, int((*q)[0]) + 7, int((*q)[1]) - 7,
                                      std::to_string(i + 1), kInterpolated, 16);
    }
    return labels;
}

/// A square of side `size` world units in the plane through `centre` with unit normal `normal`.
void drawSquare(render::Image& image, const render::Camera& camera, const Vec3d& centre,
                const Vec3d& normal, double size, const render::Color& color)
{
    const Vec3d helper = std::abs(normal.y()) < 0.9 ? Vec3d(0, 1, 0) : Vec3d(1, 0, 0);
    const Vec3d u = normal.cross(helper).unit() * (0.5 * size), v = normal.cross(u);
    const Vec3d corners[4] = {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
    for (int k = 0; k < 4; ++k)
        render::drawSegment(image, camera, corners[k], corners[(k + 1) % 4], color, 1);
}

/// Each [[timing.region]]'s world bounds (its mesh imported, or its volume's header read): once
/// for the preview, not per frame.
std::vector<std::pair<Vec3d, Vec3d>> regionBounds(const Scene& scene)
{
    std::vector<std::pair<Vec3d, Vec3d>> out;
    for (const TimingRegionSpec& region : scene.timingRegions) {
        const ObjectSpec& shape = region.shape;
        if (shape.isVolume()) {
            const VolumeFileInfo info = inspectVolume(shape.volumeSource());
            out.emplace_back(info.worldMin, info.worldMax);
        } else {
            out.push_back(importMesh(shape.mesh, shape.transform, shape.fileWhere).bounds());
        }
    }
    return out;
}

/// [timing] at morph time t: the sweep's two fronts (where places start now, where they finish
/// now: between them the morph is under way), and each region's bounds (regionBounds).
void drawTiming(render::Image& image, const render::Camera& camera, const Scene& scene, double t,
                const std::vector<std::pair<Vec3d, Vec3d>>& regions)
{
    const TimingSettings& timing = scene.timing;
    if (timing.spread == 0.0) return;
    if (const auto& sweep = timing.sweep) {
        const LocalTime along(timing, {});
        const Vec3d dir = sweep->direction.unit();
        // The place along the sweep whose delay is `d` (the delay rises along it: bisection).
        const auto at = [&](double d) {
            double lo = 0.0, hi = 1.0;
            for (int k = 0; k < 40; ++k) {
                const double mid = 0.5 * (lo + hi);
                (along.delay(sweep->origin + dir * (mid * sweep->length)).d < d ? lo : hi) = mid;
            }
            return sweep->origin + dir * (lo * sweep->length);
        };
        if (t <= timing.spread) drawSquare(image, camera, at(t), dir, sweep->length, kStarting);
        if (const double done = t - (1.0 - timing.spread); done >= 0.0)
            drawSquare(image, camera, at(done), dir, sweep->length, kFinishing);
    }
    for (const auto& [lo, hi] : regions)
        for (int e = 0; e < 12; ++e) { // the box's edges: 4 along each axis
            const int axis = e / 4, a = (axis + 1) % 3, b = (axis + 2) % 3;
            Vec3d p = lo;
            if (e & 1) p[a] = hi[a];
            if (e & 2) p[b] = hi[b];
            Vec3d q = p;
            q[axis] = hi[axis];
            render::drawSegment(image, camera, p, q, kRegion, 1);
        }
}

void writeImage(const render::Image& image, const std::string& path, const render::Camera& camera,
                int frame)
{
    const std::filesystem::path file(path);
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    try {
        if (file.extension() == ".exr") {
            render::ExrOptions exr;
            exr.frame = frame;
            render::writeExr(image, camera, file, exr);
        } else {
            render::writePng(image, file);
        }
    } catch (const std::exception& e) {
        throw UserError(SourceLocation{path},
                        std::string("cannot write the preview (") + e.what() + ")");
    }
}

/// A frame read back from a rendered EXR (--from).
render::Image readFrame(const std::string& pattern, int frame)
{
    const std::filesystem::path file = frameFileName(pattern, frame);
    try {
        return render::readImage(file);
    } catch (const std::exception& e) {
        throw UserError(SourceLocation{file.string()},
                        std::string("cannot read frame ") + std::to_string(frame) + " (" +
                            e.what() + "); render it first with volmorph render");
    }
}

int runPreview(const PreviewArgs& args)
{
    const Scene scene = loadScene(args.scene);
    if (args.contactSheet == args.frame.has_value())
        throw UserError(SourceLocation{"preview"}, "give either --frame N or --contact-sheet");
    std::vector<int> frames;
    if (args.frame)
        frames = selectFrames(scene.frames, std::to_string(*args.frame), "--frame");
    else
        frames = selectFrames(scene.frames, args.frames, "--frames");
    const bool drawPairs = args.contactSheet ? args.features : !args.noFeatures;
    const int width = args.contactSheet ? args.tileWidth : args.width;

    // Frames come from existing EXRs (--from) or are morphed and rendered here.
    Interrupter interrupter(false, args.verbose);
    StopSignals signals(interrupter);
    std::optional<SceneMorph> morph;
    SceneRender view(scene, args.threads, width);
    view.settings.interrupter = &interrupter;
    if (args.samples) view.settings.samples = *args.samples;
    view.settings.layers = false; // a preview is RGBA alone
    if (args.from.empty())
        morph.emplace(scene, args.cache, interrupter, MorphOptions{}, args.quiet);
    else if (const std::string why = checkFramePattern(args.from); !why.empty())
        throw UserError(SourceLocation{"--from"}, "\"" + args.from + "\": " + why);

    std::vector<render::Image> images;
    std::vector<std::string> labels;
    bool labelsDrawn = true;
    const auto regions = drawPairs ? regionBounds(scene) : std::vector<std::pair<Vec3d, Vec3d>>{};
    FrameLoop loop(scene, frames, 1, args.quiet, false, interrupter);
    loop.run([&](const FrameStep& step) {
        render::Image image =
            morph ? renderMorphFrame(view, *morph, step.frame) : readFrame(args.from, step.frame);
        if (drawPairs) {
            // Features are drawn at the image's own size (a frame read from disk keeps its size).
            const SceneRender atSize(scene, 0, image.width);
            labelsDrawn =
                drawFeatures(image, atSize.camera(step.frame), scene, step.t, args.sides) &&
                labelsDrawn;
            drawTiming(image, atSize.camera(step.frame), scene, step.t, regions);
        }
        char label[64];
        std::snprintf(label, sizeof label, "frame %d  t=%.3f", step.frame, step.t);
        images.push_back(std::move(image));
        labels.push_back(label);
        return FrameResult{};
    });
    if (!labelsDrawn)
        std::fprintf(stderr,
                     "volmorph: warning: no font (DejaVu Sans, Debian package fonts-dejavu-core); "
                     "pair numbers are not drawn\n");

    if (args.contactSheet) {
        const render::Image sheet =
            render::contactSheet(images, labels, args.columns, args.tileWidth, kBackground);
        writeImage(sheet, args.output, view.camera(frames.front()), frames.front());
    } else {
        writeImage(render::overBackground(images.front(), kBackground), args.output,
                   view.camera(frames.front()), frames.front());
    }
    if (!args.quiet)
        std::printf("wrote %s (%zu frame%s)\n", args.output.c_str(), frames.size(),
                    frames.size() == 1 ? "" : "s");
    return 0;
}

} // namespace

Command addPreviewCommand(CLI::App& app)
{
    auto a = std::make_shared<PreviewArgs>();
    CLI::App* sub = app.add_subcommand(
        "preview",
        "A frame with the feature pairs drawn on it (PNG), or a contact sheet of frames");
    sub->add_option("SCENE", a->scene, "scene file (TOML)")->required();
    sub->add_option("-o,--output", a->output, "output image (.png: sRGB 8-bit; .exr: linear)")
        ->required();
    sub->add_option("--frame", a->frame, "the frame to show, with its features");
    sub->add_flag("--contact-sheet", a->contactSheet, "a grid of frames instead of one");
    sub->add_option("--frames", a->frames, "contact sheet frames, e.g. 1-48x4 (default: all)");
    sub->add_option("--columns", a->columns, "contact sheet columns (default 6)")
        ->check(CLI::Range(1, 64));
    sub->add_option("--tile-width", a->tileWidth,
                    "contact sheet tile width in pixels (default 240)")
        ->check(CLI::Range(16, 4096));
    sub->add_option("--from", a->from,
                    "read the frames from these EXRs (e.g. out/f.####.exr) instead of rendering");
    sub->add_flag("--sides", a->sides,
                  "also draw the source-side (blue) and target-side (pink) elements");
    sub->add_flag("--no-features", a->noFeatures, "--frame: the frame alone");
    sub->add_flag("--features", a->features, "--contact-sheet: draw the features on every tile");
    sub->add_option("--width", a->width, "--frame: image width in pixels (default: the scene's)")
        ->check(CLI::Range(16, 16384));
    sub->add_option("--samples", a->samples, "samples per pixel (default: the scene's)")
        ->check(CLI::Range(1, 4096));
    sub->add_option("--threads", a->threads, "threads (0 = all cores)")->check(CLI::Range(0, 1024));
    addCacheOptions(sub, a->cache);
    sub->add_flag("-q,--quiet", a->quiet, "print nothing on success");
    sub->add_flag("-v,--verbose", a->verbose,
                  "print each stage as it starts, with the time since the start (stderr)");
    return {sub, [a] { return runPreview(*a); }};
}

} // namespace volmorph::cli
