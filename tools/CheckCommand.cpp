// volmorph check SCENE: validate a scene and summarise it.
#include "Common.h"
#include "SceneRender.h"

#include <volmorph/Frames.h>
#include <volmorph/Scene.h>
#include <volmorph/SurfaceMorph.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/Schedule.h>
#include <volmorph/VolumeInput.h>
#include <volmorph/Voxelize.h>
#include <volmorph/render/EnvironmentMap.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <tuple>

namespace volmorph::cli {
namespace {

void printMesh(const char* label, const ObjectSpec& spec, const Mesh& mesh)
{
    const auto [lo, hi] = mesh.bounds();
    const MeshReport& r = mesh.report;
    std::printf("%-7s %s\n", label, spec.mesh.string().c_str());
    std::printf("        %zu vertices, %zu triangles, %s\n", mesh.points.size(),
                mesh.triangles.size(), describeTopology(r).c_str());
    if (r.degenerateTriangles)
        std::printf("        repaired: %zu degenerate (zero-area) triangles dropped\n",
                    r.degenerateTriangles);
    std::printf("        bounds %s .. %s world units\n", fmt(lo).c_str(), fmt(hi).c_str());
    if (spec.color)
        std::printf("        colour %s (constant)\n", fmt(*spec.color).c_str());
    else if (mesh.hasColors())
        std::printf("        colour from the mesh's vertex colours\n");
}

/// A volume input: the grids that play each part, those carried, those left out.
/// Returns the side's extent (each volume file is read once).
SideExtent printVolumeInput(const char* label, const ObjectSpec& spec, int firstFrame)
{
    ObjectSpec first = spec;
    first.volume = spec.volumeAt(firstFrame);
    first.volumeFrames.clear();
    const VolumeFileInfo info = inspectVolume(first.volumeSource());
    auto name = [](const std::string& n, const char* otherwise) {
        return n.empty() ? std::string(otherwise) : "'" + n + "'";
    };
    std::printf("%-7s %s\n", label, spec.volume.string().c_str());
    if (spec.isSequence())
        std::printf("        a sequence: frames %s on disk, held outside them; the grid and the "
                    "parts below are frame %d's (%s)\n",
                    formatFrames(spec.volumeFrames).c_str(), firstFrame,
                    first.volume.filename().string().c_str());
    std::printf("        density %s, sdf %s, colour %s\n",
                name(info.density, "from the sdf").c_str(),
                name(info.sdf, "none (derived from the density in sdf mode)").c_str(),
                name(info.color, spec.color ? "the scene's" : "grey").c_str());
    std::string carried, ignored;
    for (const std::string& n : info.extras) carried += " " + n;
    for (const std::string& n : info.ignored) ignored += " " + n;
    if (!carried.empty()) std::printf("        carried:%s\n", carried.c_str());
    if (!ignored.empty()) std::printf("        left out (not float or vec3):%s\n", ignored.c_str());
    std::printf("        voxel size %s world units; bounds %s .. %s world units\n",
                fmt(info.voxelSize).c_str(), fmt(info.worldMin).c_str(),
                fmt(info.worldMax).c_str());
    return SideExtent{info.worldMin, info.worldMax, info.voxelSize};
}

/// Hand-placed features far from their side are usually a typo in a coordinate.
void warnFarFeatures(const Scene& scene, const SideExtent& source, const SideExtent& target)
{
    auto outside = [](const Vec3d& p, const std::pair<Vec3d, Vec3d>& b) {
        const Vec3d size = b.second - b.first;
        const double margin = 0.5 * std::max({size.x(), size.y(), size.z()});
        for (int i = 0; i < 3; ++i)
            if (p[i] < b.first[i] - margin || p[i] > b.second[i] + margin) return true;
        return false;
    };
    const std::pair<Vec3d, Vec3d> sb{source.lo, source.hi}, tb{target.lo, target.hi};
    for (size_t i = 0; i < scene.pairs.size(); ++i) {
        const FeaturePairSpec& pair = scene.pairs[i];
        if (outside(pair.source.origin, sb))
            std::fprintf(stderr,
                         "%s: warning: pair %zu: source origin %s is far outside the source\n",
                         pair.where.str().c_str(), i + 1, fmt(pair.source.origin).c_str());
        if (outside(pair.target.origin, tb))
            std::fprintf(stderr,
                         "%s: warning: pair %zu: target origin %s is far outside the target\n",
                         pair.where.str().c_str(), i + 1, fmt(pair.target.origin).c_str());
    }
}

/// Two pairs with the same element on one side are legal (their weights add up) but almost always
/// a copy-paste slip; pairs whose source and target elements are both the same pull in two
/// directions from one place.
void warnCoincidentFeatures(const Scene& scene)
{
    auto same = [](const FeatureElement& a, const FeatureElement& b) {
        constexpr double kTolerance = 1e-9;
        return (a.origin - b.origin).length() < kTolerance &&
               (a.xAxis - b.xAxis).length() < kTolerance &&
               (a.yAxis - b.yAxis).length() < kTolerance &&
               (a.scale - b.scale).length() < kTolerance;
    };
    for (size_t j = 1; j < scene.pairs.size(); ++j)
        for (size_t i = 0; i < j; ++i) {
            const FeaturePairSpec& a = scene.pairs[i];
            const FeaturePairSpec& b = scene.pairs[j];
            if (a.type != b.type) continue;
            const bool s = same(a.source, b.source), t = same(a.target, b.target);
            if (!s && !t) continue;
            std::fprintf(stderr, "%s: warning: pair %zu has the same %s element as pair %zu%s\n",
                         b.where.str().c_str(), j + 1,
                         s && t ? "source and target"
                         : s    ? "source"
                                : "target",
                         i + 1,
                         s && t ? " (a duplicate: its weight counts twice)"
                         : s    ? ": one place is sent to two destinations, which are averaged"
                                : ": two places are sent to one destination");
        }
}

/// The voxel grid both sides share and the memory voxelizing the meshes takes.
void printVolume(const Scene& scene, const SceneMeshes& meshes, const SideExtent& source,
                 const SideExtent& target)
{
    const Vec3d extent = maxComponent(source.hi, target.hi) - minComponent(source.lo, target.lo);
    const double voxel = sceneVoxelSize(scene.volume, source, target);
    std::printf("volume  voxel size %s world units; both sides span %.0f x %.0f x %.0f voxels\n",
                fmt(voxel).c_str(), std::ceil(extent.x() / voxel), std::ceil(extent.y() / voxel),
                std::ceil(extent.z() / voxel));
    const double gib = double(1ull << 30);
    auto bytes = [&](const ObjectSpec& spec, const Mesh& mesh) {
        return spec.isVolume() ? 0.0 : double(estimateVoxelizeBytes(mesh, voxel, 3.0f)) / gib;
    };
    std::printf(
        "        voxelizing needs about %.2f + %.2f GiB (limit %.1f GiB, half the memory)\n",
        bytes(scene.source, meshes.source), bytes(scene.target, meshes.target),
        double(defaultMemoryLimitBytes()) / gib);
}

/// Every feature pair, numbered as the warp and `preview` number them.
void printPairs(const Scene& scene)
{
    if (scene.pairs.empty())
        std::printf(
            "pairs   0 (the identity warp); `volmorph pairs suggest %s` proposes first ones\n",
            scene.file.string().c_str());
    else
        std::printf("pairs   %zu\n", scene.pairs.size());
    for (size_t i = 0; i < scene.pairs.size(); ++i) {
        const FeaturePairSpec& p = scene.pairs[i];
        auto element = [&p](const FeatureElement& e) {
            std::string s = "origin " + fmt(e.origin);
            if (p.type != FeatureType::Point)
                s += ", x axis " + fmt(e.xAxis) + ", scale " + fmt(e.scale);
            return s;
        };
        std::printf("  %3zu %-9s source %s\n      %-9s target %s\n", i + 1, toString(p.type),
                    element(p.source).c_str(), "", element(p.target).c_str());
    }
}

/// The warp, blend and render settings.
void printSettings(const Scene& scene)
{
    const WarpSpec& w = scene.warp;
    std::printf("warp    %s, epsilon %s world units, tolerance %s voxels%s\n",
                w.weighting == Weighting::InverseSquare ? "inverse-square" : "beier-neely",
                fmt(w.epsilon).c_str(), fmt(w.toleranceVoxels).c_str(),
                w.toleranceVoxels == 0.0 ? " (exact)" : "");
    const BlendSpec& b = scene.blend;
    std::printf("blend   %s mode; density %s, colour %s, sdf %s\n",
                b.mode == BlendMode::Sdf           ? "sdf"
                : b.mode == BlendMode::Variational ? "variational"
                : b.mode == BlendMode::Surface     ? "surface"
                                                   : "density",
                describe(b.density).c_str(), describe(b.color).c_str(), describe(b.sdf).c_str());
    if (b.mode == BlendMode::Variational) {
        const VariationalSpec& v = b.variational;
        std::printf("        %d constraints per shape, normal offset %s voxels, time scale %s; "
                    "feature pairs not used\n",
                    v.constraints, fmt(v.normalOffsetVoxels).c_str(),
                    v.timeScale ? (fmt(*v.timeScale) + " world units").c_str()
                                : "from the shapes' size");
        for (const InfluenceSpec& i : scene.influences)
            std::printf("        influence at t = %s: %s\n", fmt(i.t).c_str(),
                        i.object.file().string().c_str());
    }
    for (const auto& [name, grid] : b.grids)
        std::printf("        carried grid %s: %s\n", name.c_str(), describe(grid.schedule).c_str());
    const RenderSpec& r = scene.render;
    const std::string samples =
        r.noise > 0.0 ? "noise target " + fmt(r.noise) + (r.denoise ? " (denoised)" : "") +
                            ", at most " + std::to_string(r.samples) + " samples"
                      : std::to_string(r.samples) + " samples";
    std::printf("render  %dx%d, %s, step %s voxels, extinction %s per world unit, albedo %s\n",
                r.width, r.height, samples.c_str(), fmt(r.stepVoxels).c_str(),
                fmt(r.extinction).c_str(), fmt(r.albedo).c_str());
    if (r.bounces > 0)
        std::printf("        multiple scattering, %d bounces", r.bounces);
    else
        std::printf("        single scattering (bounces = 0)");
    const bool paths = r.bounces > 0 || std::any_of(r.lights.begin(), r.lights.end(), [](auto& l) {
                           return l.type == LightType::Environment;
                       });
    if (paths)
        std::printf("; paths, ratio tracking toward lights\n");
    else if (r.shadowCacheVoxels == 1)
        std::printf("; shadow caches every voxel\n");
    else if (r.shadowCacheVoxels > 1)
        std::printf("; shadow caches every %d voxels\n", r.shadowCacheVoxels);
    else
        std::printf("; exact transmittance toward lights\n");
}

/// Surface mode: the correspondence the meshes get (auto resolved) and how vertices travel.
void printSurface(const Scene& scene, const SceneMeshes& meshes)
{
    // The correspondence is what check tries (or a UserError); the in-betweens' factorization
    // is the morph's work, so the straight line stands in for it here.
    SurfaceSpec correspondenceOnly = scene.surface;
    correspondenceOnly.interpolation = SurfaceInterpolation::Linear;
    const SurfaceMorpher m(meshes.source, meshes.target, correspondenceOnly);
    const std::string used = name(m.correspondence());
    std::string merged;
    if (m.correspondence() != Correspondence::Identity)
        merged = " (" + std::to_string(m.vertexCount() - m.crossings()) + " of the inputs, " +
                 std::to_string(m.crossings()) + " where their edges cross)";
    std::printf("surface %s correspondence%s: %zu vertices%s, %zu triangles at every frame; %s "
                "interpolation (positions on the sdf schedule, colours on the colour schedule)\n",
                used.c_str(), scene.surface.correspondence == Correspondence::Auto ? " (auto)" : "",
                m.vertexCount(), merged.c_str(), m.triangleCount(),
                name(scene.surface.interpolation));
    if (const auto k = m.kernels())
        std::printf("        projected from %s (source) and %s (target), world units%s\n",
                    fmt(k->first).c_str(), fmt(k->second).c_str(),
                    scene.surface.kernel ? "" : ": each mesh's deepest kernel point");
    if (const auto s = m.stretchEfficiency())
        std::printf("        spherical maps' L2 stretch efficiency %.3f (source), %.3f (target); 1 "
                    "would be no stretch\n",
                    s->first, s->second);
    if (!scene.pairs.empty() && m.correspondence() == Correspondence::Identity)
        std::printf("        %zu landmark pairs: not used by the identity (vertex i is vertex i)\n",
                    scene.pairs.size());
    else if (!scene.pairs.empty())
        std::printf("        %zu landmark pairs meet: each snapped to its surface, the target's "
                    "point a vertex\n",
                    scene.pairs.size());
}

/// An environment light, and its sky map's size once read.
void printEnvironment(const LightSpec& l)
{
    std::printf("light   environment, colour %s, intensity %s (radiance)", fmt(l.color).c_str(),
                fmt(l.intensity).c_str());
    if (const auto map = readSkyMap(l))
        std::printf(", times the lat-long map %s (%dx%d)", l.map.filename().string().c_str(),
                    map->width(), map->height());
    std::printf("\n");
}

/// The camera, the emission and the lights (with their animation keys).
void printView(const RenderSpec& r)
{
    const CameraSpec& c = r.camera;
    if (c.projection == Projection::Perspective)
        std::printf("camera  perspective, eye %s, lookat %s, fov %s degrees (horizontal)\n",
                    fmt(c.eye).c_str(), fmt(c.lookat).c_str(), fmt(c.fovDegrees).c_str());
    else
        std::printf("camera  orthographic, eye %s, lookat %s, width %s world units\n",
                    fmt(c.eye).c_str(), fmt(c.lookat).c_str(), fmt(c.orthoWidth).c_str());
    if (!c.keys.empty())
        std::printf("        animated: %zu keys, frames %d to %d\n", c.keys.size(),
                    c.keys.front().frame, c.keys.back().frame);
    if (r.emission != Vec3d(0.0))
        std::printf("emission %s per unit optical depth\n", fmt(r.emission).c_str());
    for (const LightSpec& l : r.lights) {
        if (l.type == LightType::Directional)
            std::printf(
                "light   directional, travelling %s, colour %s, intensity %s%s\n",
                fmt(l.direction).c_str(), fmt(l.color).c_str(), fmt(l.intensity).c_str(),
                l.angleRadians > 0.0
                    ? (", " + fmt(l.angleRadians * 180.0 / M_PI) + " degrees across").c_str()
                    : "");
        else if (l.type == LightType::Environment)
            printEnvironment(l);
        else
            std::printf("light   point at %s, colour %s, intensity %s\n", fmt(l.position).c_str(),
                        fmt(l.color).c_str(), fmt(l.intensity).c_str());
        if (!l.keys.empty())
            std::printf("        animated: %zu keys, frames %d to %d\n", l.keys.size(),
                        l.keys.front().frame, l.keys.back().frame);
    }
}

/// [timing]: the spread, the sweep and each region (its file checked here, at its key).
void printTiming(const Scene& scene)
{
    const TimingSettings& t = scene.timing;
    if (t.spread == 0.0 && scene.timingRegions.empty()) return;
    checkTimingRegions(scene);
    std::printf("timing  spread %s: the last place starts %s of the morph after the first; each "
                "place morphs over %s of it\n",
                fmt(t.spread).c_str(), fmt(t.spread).c_str(), fmt(1.0 - t.spread).c_str());
    if (t.sweep)
        std::printf("        sweep from %s along %s: the delay rises from 0 at that plane to %s "
                    "at %s world units along\n",
                    fmt(t.sweep->origin).c_str(), fmt(t.sweep->direction).c_str(),
                    fmt(t.spread).c_str(), fmt(t.sweep->length).c_str());
    for (size_t i = 0; i < scene.timingRegions.size(); ++i) {
        const TimingRegionSpec& r = scene.timingRegions[i];
        std::printf("        region %zu %s: delay %s inside, fading over %s world units outside\n",
                    i + 1, r.shape.file().string().c_str(), fmt(r.start).c_str(),
                    fmt(r.softness).c_str());
    }
}

/// The frame range, the output pattern and every frame's t.
void printFrames(const Scene& scene)
{
    const FramesSpec& f = scene.frames;
    std::printf("frames  %d-%d (%d frames) -> %s\n", f.first, f.last, f.count(),
                (scene.folder / f.output).string().c_str());
    constexpr int kPerLine = 8;
    for (int frame = f.first; frame <= f.last; ++frame) {
        const int k = frame - f.first;
        std::printf("%s%5d: t=%-7.4f", k % kPerLine == 0 ? "       " : "", frame, f.t(frame));
        if (k % kPerLine == kPerLine - 1 || frame == f.last) std::printf("\n");
    }
}

/// Each [[prop]]: its mesh read (so that a bad one is refused here, at its key), its role.
void printProps(const Scene& scene)
{
    for (size_t i = 0; i < scene.props.size(); ++i) {
        const PropSpec& prop = scene.props[i];
        const Mesh mesh = importMesh(prop.mesh, prop.transform, prop.where);
        std::printf("prop %zu  %s: %zu triangles, %s, colour %g %g %g\n", i + 1,
                    prop.mesh.filename().string().c_str(), mesh.triangles.size(),
                    prop.holdout         ? "holdout"
                    : prop.shadowCatcher ? "shadow catcher"
                                         : "diffuse",
                    prop.color.x(), prop.color.y(), prop.color.z());
    }
}

int runCheck(const std::string& scenePath)
{
    const Scene scene = loadScene(scenePath);
    const SceneMeshes meshes = importSceneMeshes(scene);
    std::printf("scene   %s\n", scenePath.c_str());
    SideExtent source, target;
    for (auto [label, spec, mesh, extent] :
         {std::tuple{"source", &scene.source, &meshes.source, &source},
          std::tuple{"target", &scene.target, &meshes.target, &target}}) {
        if (spec->isVolume()) {
            *extent = printVolumeInput(label, *spec, scene.frames.first);
        } else {
            printMesh(label, *spec, *mesh);
            std::tie(extent->lo, extent->hi) = mesh->bounds();
        }
    }
    printVolume(scene, meshes, source, target);
    printPairs(scene);
    printSettings(scene);
    printTiming(scene);
    if (scene.blend.mode == BlendMode::Surface) printSurface(scene, meshes);
    printView(scene.render);
    printProps(scene);
    printFrames(scene);
    std::fflush(stdout);
    warnFarFeatures(scene, source, target);
    warnCoincidentFeatures(scene);
    return 0;
}

} // namespace

Command addCheckCommand(CLI::App& app)
{
    auto scene = std::make_shared<std::string>();
    CLI::App* sub = app.add_subcommand("check", "Validate a scene file and summarise it");
    sub->add_option("SCENE", *scene, "scene file (TOML)")->required();
    return {sub, [scene] { return runCheck(*scene); }};
}

} // namespace volmorph::cli
