// The volmorph command-line program: a thin shell of subcommands over libvolmorph.
//
// Exit status: 0 success, 1 a user error (each problem on stderr as FILE:LINE:COL: message),
// 2 bad command-line usage (CLI11), 70 an internal error.
#include <volmorph/Interrupter.h>
#include <volmorph/Mesh.h>
#include <volmorph/Scene.h>
#include <volmorph/Version.h>
#include <volmorph/Voxelize.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <csignal>
#include <unistd.h>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

namespace {

using namespace volmorph;

constexpr int kExitUserError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitInternal = 70;
constexpr int kExitInterrupted = 130; // as a shell reports a SIGINT

/// The interrupter SIGINT and SIGTERM stop; set while a long operation runs.
volmorph::Interrupter* gInterrupter = nullptr;

extern "C" void onStopSignal(int)
{
    if (gInterrupter) gInterrupter->requestStop();
}

/// Routes SIGINT and SIGTERM to `interrupter` for the lifetime of this object.
class StopSignals {
public:
    explicit StopSignals(volmorph::Interrupter& interrupter)
    {
        gInterrupter = &interrupter;
        struct sigaction action {};
        action.sa_handler = onStopSignal;
        sigemptyset(&action.sa_mask);
        sigaction(SIGINT, &action, &mOldInt);
        sigaction(SIGTERM, &action, &mOldTerm);
    }
    ~StopSignals()
    {
        sigaction(SIGINT, &mOldInt, nullptr);
        sigaction(SIGTERM, &mOldTerm, nullptr);
        gInterrupter = nullptr;
    }

private:
    struct sigaction mOldInt {}, mOldTerm {};
};

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
    const SceneMeshes meshes = importSceneMeshes(scene);
    std::printf("scene   %s\n", scenePath.c_str());
    printMesh("source", scene.source, meshes.source);
    printMesh("target", scene.target, meshes.target);

    auto [slo, shi] = meshes.source.bounds();
    auto [tlo, thi] = meshes.target.bounds();
    const Vec3d extent = maxComponent(shi, thi) - minComponent(slo, tlo);
    const double voxel = sceneVoxelSize(scene.volume, meshes.source, meshes.target);
    std::printf("volume  voxel size %s world units; both meshes span %.0f x %.0f x %.0f voxels\n",
                fmt(voxel).c_str(), std::ceil(extent.x() / voxel), std::ceil(extent.y() / voxel),
                std::ceil(extent.z() / voxel));
    const double gib = double(1ull << 30);
    std::printf("        voxelizing needs about %.2f + %.2f GiB (limit %.1f GiB, half the memory)\n",
                double(estimateVoxelizeBytes(meshes.source, voxel, 3.0f)) / gib,
                double(estimateVoxelizeBytes(meshes.target, voxel, 3.0f)) / gib,
                double(defaultMemoryLimitBytes()) / gib);

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
    warnFarFeatures(scene, meshes.source, meshes.target);
    return 0;
}

struct VoxelizeArgs {
    std::string mesh, output, sign = "auto";
    std::optional<double> voxelSize;
    std::optional<int> resolution;
    float halfWidth = 3.0f;
    std::vector<float> color;
    double memoryLimitGiB = 0.0;
    bool quiet = false;
};

int runVoxelize(const VoxelizeArgs& args)
{
    const Mesh mesh = importMesh(args.mesh);
    VoxelizeOptions options;
    options.voxelSize = args.voxelSize;
    if (args.resolution) options.resolution = *args.resolution;
    options.halfWidthVoxels = args.halfWidth;
    if (!args.color.empty()) options.color = Vec3f(args.color[0], args.color[1], args.color[2]);
    options.memoryLimitBytes = uint64_t(args.memoryLimitGiB * double(1ull << 30));
    options.sign = args.sign == "winding"     ? VoxelizeOptions::Sign::WindingNumber
                   : args.sign == "floodfill" ? VoxelizeOptions::Sign::FloodFill
                                              : VoxelizeOptions::Sign::Auto;
    const std::filesystem::path output(args.output);
    const std::filesystem::path folder = output.has_parent_path() ? output.parent_path() : ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
        throw UserError(SourceLocation{args.output}, "the output folder does not exist");

    Interrupter interrupter(!args.quiet && isatty(fileno(stderr)));
    StopSignals signals(interrupter);
    VoxelizeStats stats;
    const auto start = std::chrono::steady_clock::now();
    const VolumeSet volumes = voxelize(mesh, options, &interrupter, &stats);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (interrupter.stopRequested()) throw Interrupted();
    std::ostringstream voxel;
    voxel << stats.voxelSize;
    writeVolumeSet(volumes, output,
                   {{"volmorph_source", std::filesystem::absolute(args.mesh).string()},
                    {"volmorph_voxel_size", voxel.str()},
                    {"volmorph_sign", stats.usedWindingNumber ? "winding number" : "flood fill"},
                    {"volmorph_version", versionString()}});
    if (!args.quiet) {
        std::printf("%s: %zu triangles, %s\n", args.mesh.c_str(), mesh.triangles.size(),
                    describeTopology(mesh.report).c_str());
        std::printf("voxel size %s world units; inside/outside by %s\n", voxel.str().c_str(),
                    stats.usedWindingNumber ? "winding number" : "flood fill (watertight, one shell)");
        std::printf("sdf %llu active voxels, density %llu active voxels, %.2f s\n",
                    (unsigned long long)stats.sdfActiveVoxels, (unsigned long long)stats.densityActiveVoxels,
                    seconds);
        std::printf("wrote %s (grids sdf, density, Cd)\n", args.output.c_str());
    }
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

    VoxelizeArgs vox;
    CLI::App* voxelizeCmd = app.add_subcommand("voxelize", "Voxelize a mesh into sdf, density and Cd grids");
    voxelizeCmd->add_option("MESH", vox.mesh, "mesh file (OBJ, PLY, STL, OFF, glTF, ...)")->required();
    voxelizeCmd->add_option("-o,--output", vox.output, "output .vdb file")->required();
    auto* sizeOpt = voxelizeCmd->add_option("--voxel-size", vox.voxelSize, "voxel edge in world units")
                        ->check(CLI::PositiveNumber);
    voxelizeCmd->add_option("--resolution", vox.resolution, "voxels across the longest side (default 128)")
        ->check(CLI::Range(8, 16384))
        ->excludes(sizeOpt);
    voxelizeCmd->add_option("--half-width", vox.halfWidth, "narrow band half width in voxels (>= 3)")
        ->check(CLI::Range(3.0f, 64.0f));
    voxelizeCmd->add_option("--color", vox.color, "constant linear RGB colour R,G,B")
        ->delimiter(',')
        ->expected(3);
    voxelizeCmd->add_option("--memory-limit", vox.memoryLimitGiB,
                            "refuse above this estimate, in GiB (default: half the machine's memory)")
        ->check(CLI::PositiveNumber);
    voxelizeCmd->add_option("--sign", vox.sign, "inside/outside: auto, floodfill or winding")
        ->check(CLI::IsMember({"auto", "floodfill", "winding"}));
    voxelizeCmd->add_flag("-q,--quiet", vox.quiet, "print nothing on success");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version arrive here too, with status 0; misuse is always status 2.
        return app.exit(e) == 0 ? 0 : kExitUsage;
    }

    try {
        if (*check) return runCheck(scenePath);
        if (*voxelizeCmd) return runVoxelize(vox);
    } catch (const volmorph::Interrupted&) {
        std::fprintf(stderr, "volmorph: interrupted; no output written\n");
        return kExitInterrupted;
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
