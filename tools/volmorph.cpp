// The volmorph command-line program: a thin shell of subcommands over libvolmorph.
//
// Exit status: 0 success, 1 a user error (each problem on stderr as FILE:LINE:COL: message),
// 2 bad command-line usage (CLI11), 70 an internal error.
#include <volmorph/Mesh.h>
#include <volmorph/Scene.h>
#include <volmorph/Version.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace {

using namespace volmorph;

constexpr int kExitUserError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitInternal = 70;

std::string fmt(double v)
{
    std::ostringstream s;
    s.precision(4);
    s << v;
    return s.str();
}

std::string fmt(const Vec3d& v)
{
    return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]";
}

std::string describeTopology(const MeshReport& r)
{
    std::ostringstream s;
    if (r.watertight()) s << "watertight";
    else {
        s << "open";
        if (r.boundaryEdges) s << ", " << r.boundaryEdges << " boundary edges";
        if (r.nonManifoldEdges) s << ", " << r.nonManifoldEdges << " non-manifold edges";
    }
    if (!r.consistentlyOriented()) s << ", " << r.misorientedEdges << " inconsistently oriented edges";
    s << ", " << r.components << (r.components == 1 ? " shell" : " shells");
    return s.str();
}

void printMesh(const char* label, const ObjectSpec& spec, const Mesh& mesh)
{
    const auto [lo, hi] = mesh.bounds();
    const MeshReport& r = mesh.report;
    std::printf("%-7s %s\n", label, spec.mesh.string().c_str());
    std::printf("        %zu vertices, %zu triangles, %s\n", mesh.points.size(), mesh.triangles.size(),
                describeTopology(r).c_str());
    if (r.degenerateTriangles)
        std::printf("        repaired: %zu degenerate (zero-area) triangles dropped\n",
                    r.degenerateTriangles);
    std::printf("        bounds %s .. %s world units\n", fmt(lo).c_str(), fmt(hi).c_str());
    if (spec.color) std::printf("        colour %s (constant)\n", fmt(*spec.color).c_str());
    else if (mesh.hasColors()) std::printf("        colour from the mesh's vertex colours\n");
}

/// Hand-placed features far from their mesh are usually a typo in a coordinate.
void warnFarFeatures(const Scene& scene, const Mesh& source, const Mesh& target)
{
    auto outside = [](const Vec3d& p, const std::pair<Vec3d, Vec3d>& b) {
        const Vec3d size = b.second - b.first;
        const double margin = 0.5 * std::max({size.x(), size.y(), size.z()});
        for (int i = 0; i < 3; ++i)
            if (p[i] < b.first[i] - margin || p[i] > b.second[i] + margin) return true;
        return false;
    };
    const auto sb = source.bounds(), tb = target.bounds();
    for (size_t i = 0; i < scene.pairs.size(); ++i) {
        const FeaturePairSpec& pair = scene.pairs[i];
        if (outside(pair.source.origin, sb))
            std::fprintf(stderr, "%s: warning: pair %zu: source origin %s is far outside the source mesh\n",
                         pair.where.str().c_str(), i + 1, fmt(pair.source.origin).c_str());
        if (outside(pair.target.origin, tb))
            std::fprintf(stderr, "%s: warning: pair %zu: target origin %s is far outside the target mesh\n",
                         pair.where.str().c_str(), i + 1, fmt(pair.target.origin).c_str());
    }
}

int runCheck(const std::string& scenePath)
{
    const Scene scene = loadScene(scenePath);
    // Import both meshes before reporting, so that both are checked even when one fails.
    std::vector<Diagnostic> problems;
    Mesh meshes[2];
    const ObjectSpec* specs[2] = {&scene.source, &scene.target};
    for (int i = 0; i < 2; ++i) {
        try {
            meshes[i] = importMesh(specs[i]->mesh, specs[i]->transform, specs[i]->meshWhere);
        } catch (const UserError& e) {
            problems.insert(problems.end(), e.diagnostics().begin(), e.diagnostics().end());
        }
    }
    if (!problems.empty()) throw UserError(problems);

    std::printf("scene   %s\n", scenePath.c_str());
    printMesh("source", scene.source, meshes[0]);
    printMesh("target", scene.target, meshes[1]);

    auto [slo, shi] = meshes[0].bounds();
    auto [tlo, thi] = meshes[1].bounds();
    Vec3d lo = minComponent(slo, tlo), hi = maxComponent(shi, thi);
    const Vec3d extent = hi - lo;
    const double longest = std::max({extent.x(), extent.y(), extent.z()});
    const double voxel = scene.volume.voxelSize ? *scene.volume.voxelSize
                                                : longest / double(*scene.volume.resolution);
    std::printf("volume  voxel size %s world units; both meshes span %.0f x %.0f x %.0f voxels\n",
                fmt(voxel).c_str(), std::ceil(extent.x() / voxel), std::ceil(extent.y() / voxel),
                std::ceil(extent.z() / voxel));

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
    const WarpSpec& w = scene.warp;
    std::printf("warp    %s, epsilon %s world units, tolerance %s voxels%s\n",
                w.weighting == Weighting::InverseSquare ? "inverse-square" : "beier-neely",
                fmt(w.epsilon).c_str(), fmt(w.toleranceVoxels).c_str(),
                w.toleranceVoxels == 0.0 ? " (exact)" : "");
    const BlendSpec& b = scene.blend;
    std::printf("blend   %s mode; density %s, colour %s, sdf %s\n",
                b.mode == BlendMode::Sdf ? "sdf" : "density", b.density.str().c_str(),
                b.color.str().c_str(), b.sdf.str().c_str());
    const RenderSpec& r = scene.render;
    std::printf("render  %dx%d, %d samples, step %s voxels, extinction %s per world unit, albedo %s\n",
                r.width, r.height, r.samples, fmt(r.stepVoxels).c_str(), fmt(r.extinction).c_str(),
                fmt(r.albedo).c_str());
    const CameraSpec& c = r.camera;
    if (c.projection == Projection::Perspective)
        std::printf("camera  perspective, eye %s, lookat %s, fov %s degrees (horizontal)\n",
                    fmt(c.eye).c_str(), fmt(c.lookat).c_str(), fmt(c.fovDegrees).c_str());
    else
        std::printf("camera  orthographic, eye %s, lookat %s, width %s world units\n",
                    fmt(c.eye).c_str(), fmt(c.lookat).c_str(), fmt(c.orthoWidth).c_str());
    for (const LightSpec& l : r.lights) {
        if (l.type == LightType::Directional)
            std::printf("light   directional, travelling %s, colour %s, intensity %s\n",
                        fmt(l.direction).c_str(), fmt(l.color).c_str(), fmt(l.intensity).c_str());
        else
            std::printf("light   point at %s, colour %s, intensity %s\n", fmt(l.position).c_str(),
                        fmt(l.color).c_str(), fmt(l.intensity).c_str());
    }
    const FramesSpec& f = scene.frames;
    std::printf("frames  %d-%d (%d frames) -> %s\n", f.first, f.last, f.count(),
                (scene.folder / f.output).string().c_str());
    constexpr int kPerLine = 8;
    for (int frame = f.first; frame <= f.last; ++frame) {
        const int k = frame - f.first;
        std::printf("%s%5d: t=%-7.4f", k % kPerLine == 0 ? "       " : "", frame, f.t(frame));
        if (k % kPerLine == kPerLine - 1 || frame == f.last) std::printf("\n");
    }
    std::fflush(stdout);
    warnFarFeatures(scene, meshes[0], meshes[1]);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"volmorph: feature-based volumetric morphing of meshes through OpenVDB grids"};
    app.set_version_flag("--version", std::string("volmorph ") + volmorph::versionString());
    app.require_subcommand(1);

    std::string scenePath;
    CLI::App* check = app.add_subcommand("check", "Validate a scene file and summarise it");
    check->add_option("SCENE", scenePath, "scene file (TOML)")->required();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version arrive here too, with status 0; misuse is always status 2.
        return app.exit(e) == 0 ? 0 : kExitUsage;
    }

    try {
        if (*check) return runCheck(scenePath);
    } catch (const volmorph::UserError& e) {
        for (const volmorph::Diagnostic& d : e.diagnostics())
            std::fprintf(stderr, "%s\n", d.str().c_str());
        return kExitUserError;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "volmorph: out of memory\n");
        return kExitInternal;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "volmorph: internal error: %s\n", e.what());
        return kExitInternal;
    }
    return 0;
}
