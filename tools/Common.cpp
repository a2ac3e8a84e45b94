#include "Common.h"

#include <volmorph/Voxelize.h>

#include <algorithm>

#include <unistd.h>

#include <cstdio>
#include <sstream>

namespace volmorph::cli {
namespace {

/// The interrupter SIGINT and SIGTERM stop; set while a long operation runs.
Interrupter* gInterrupter = nullptr;

extern "C" void onStopSignal(int)
{
    if (gInterrupter) gInterrupter->requestStop();
}

} // namespace

StopSignals::StopSignals(Interrupter& interrupter)
{
    gInterrupter = &interrupter;
    struct sigaction action {};
    action.sa_handler = onStopSignal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &mOldInt);
    sigaction(SIGTERM, &action, &mOldTerm);
}

StopSignals::~StopSignals()
{
    sigaction(SIGINT, &mOldInt, nullptr);
    sigaction(SIGTERM, &mOldTerm, nullptr);
    gInterrupter = nullptr;
}

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
    if (r.watertight())
        s << "watertight";
    else {
        s << "open";
        if (r.boundaryEdges) s << ", " << r.boundaryEdges << " boundary edges";
        if (r.nonManifoldEdges) s << ", " << r.nonManifoldEdges << " non-manifold edges";
    }
    if (!r.consistentlyOriented())
        s << ", " << r.misorientedEdges << " inconsistently oriented edges";
    s << ", " << r.components << (r.components == 1 ? " shell" : " shells");
    return s.str();
}

std::filesystem::path CacheArgs::resolve() const
{
    if (disabled) return {};
    if (!folder.empty()) return folder;
    return defaultCacheFolder();
}

void addCacheOptions(CLI::App* command, CacheArgs& args)
{
    command->add_option(
        "--cache", args.folder,
        "voxel cache folder (default: $VOLMORPH_CACHE, else $XDG_CACHE_HOME/volmorph, else "
        "~/.cache/volmorph); share it between the chunks of a farm job");
    command->add_flag("--no-cache", args.disabled, "voxelize without reading or writing the cache");
}

SceneVolumes loadSceneVolumes(const Scene& scene, const CacheArgs& cache, Interrupter& interrupter,
                              uint64_t memoryLimitBytes, bool quiet)
{
    const auto start = std::chrono::steady_clock::now();
    CacheReport report;
    SceneVolumes volumes =
        voxelizeSceneCached(scene, cache.resolve(), &interrupter, memoryLimitBytes, &report);
    const std::string entry = report.entry.string();
    if (report.outcome == CacheReport::Outcome::Rebuilt)
        std::fprintf(stderr, "%s: voxel cache entry not used (%s); voxelized again and replaced\n",
                     entry.c_str(), report.problem.c_str());
    if (!report.storeProblem.empty())
        std::fprintf(stderr, "volmorph: warning: the voxels were not cached: %s\n",
                     report.storeProblem.c_str());
    if (!quiet) {
        const double seconds = secondsSince(start);
        if (report.outcome == CacheReport::Outcome::Hit)
            std::printf("voxels of source and target read from the cache in %.2f s (%s)\n", seconds,
                        entry.c_str());
        else
            std::printf("voxelized source and target at %g world units in %.2f s%s%s\n",
                        volumes.source.voxelSize(), seconds,
                        report.storeProblem.empty() && !entry.empty() ? "; cached in " : "",
                        report.storeProblem.empty() ? entry.c_str() : "");
        std::fflush(stdout);
    }
    return volumes;
}

Progress::Progress(int steps, bool quiet)
    : mSteps(std::max(1, steps)), mQuiet(quiet), mTerminal(isatty(STDOUT_FILENO) == 1),
      mStart(std::chrono::steady_clock::now())
{
}

void Progress::update(int done)
{
    if (mQuiet) return;
    mLastDone = done;
    const int percent = int(100.0 * double(done) / double(mSteps));
    if (!mTerminal) {
        if (percent == mLastPercent) return;
        mLastPercent = percent;
        std::printf("ALF_PROGRESS %d%%\n", percent);
        std::fflush(stdout);
        return;
    }
    const double elapsed = secondsSince(mStart);
    const double eta = done > 0 ? elapsed * double(mSteps - done) / double(done) : 0.0;
    constexpr int kWidth = 30;
    const int filled = kWidth * done / mSteps;
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '.');
    char text[160];
    if (done > 0)
        std::snprintf(text, sizeof text, "\r[%s] %3d%%  %d/%d  elapsed %.0f s  ETA %.0f s ",
                      bar.c_str(), percent, done, mSteps, elapsed, eta);
    else
        std::snprintf(text, sizeof text, "\r[%s] %3d%%  %d/%d ", bar.c_str(), percent, done,
                      mSteps);
    std::fputs(text, stdout);
    std::fflush(stdout);
    mBarShown = true;
}

void Progress::log(const std::string& line)
{
    if (mQuiet) return;
    if (mTerminal && mBarShown)
        std::fputs("\r\033[K", stdout); // clear the bar, print, redraw below
    std::printf("%s\n", line.c_str());
    if (mTerminal && mBarShown) update(mLastDone);
    std::fflush(stdout);
}

Progress::~Progress()
{
    if (!mQuiet && mTerminal && mBarShown) std::fputs("\n", stdout);
}

void checkFilmMemory(int width, int height, double limitGiB, bool layers)
{
    // Per channel (RGBA, and the layers' 15): the film's double sums, the float image, the float
    // copy interleaved to write it, and the encoder's buffer; per pixel, the last pass's RGB
    // (doubles), the counts and the variance.
    const double bytesPerPixel = (layers ? 19.0 : 4.0) * 20.0 + 3.0 * 8.0 + 3.0 * 4.0 + 4.0;
    const double bytes = bytesPerPixel * double(width) * double(height);
    const double limit = double(memoryLimitBytes(limitGiB));
    if (bytes <= limit) return;
    char text[300];
    std::snprintf(text, sizeof text,
                  "a %dx%d image needs about %.1f GiB, more than the memory limit of %.1f GiB; "
                  "render fewer pixels or raise the memory limit",
                  width, height, bytes / double(1ull << 30), limit / double(1ull << 30));
    throw MemoryLimitExceeded(SourceLocation{"render"}, text, uint64_t(bytes), uint64_t(limit));
}

double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace volmorph::cli
