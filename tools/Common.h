// Shared pieces of the volmorph subcommands: exit codes, number formatting, stop signals.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/Mesh.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/VoxelCache.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <csignal>
#include <functional>
#include <string>

namespace volmorph::cli {

/// Exit status: 0 success, 1 a user error (each problem on stderr as FILE:LINE:COL: message),
/// 2 bad command-line usage (CLI11), 130 interrupted by SIGINT or SIGTERM, 70 an internal error.
constexpr int kExitUserError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitInternal = 70;
constexpr int kExitInterrupted = 130;

/// A subcommand: registered on the app, run after parsing when it was chosen.
struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

Command addCheckCommand(CLI::App& app);
Command addVoxelizeCommand(CLI::App& app);
Command addMorphCommand(CLI::App& app);
Command addRenderVdbCommand(CLI::App& app);
Command addRenderCommand(CLI::App& app);
Command addDiffCommand(CLI::App& app);
Command addCacheCommand(CLI::App& app);
Command addPreviewCommand(CLI::App& app);
Command addFramesCommand(CLI::App& app);
Command addPairsCommand(CLI::App& app);
Command addEditCommand(CLI::App& app);

std::string fmt(double v);
std::string fmt(const Vec3d& v);
std::string describeTopology(const MeshReport& r);

/// Refuses (UserError) to render a width x height film that would need more than the memory limit
/// (`limitGiB`, 0 = half the machine's memory): float RGBA, and the layers when asked for, plus the
/// copies made to write them.
void checkFilmMemory(int width, int height, double limitGiB, bool layers);

/// Wall-clock seconds since `start`.
double secondsSince(std::chrono::steady_clock::time_point start);

/// Where the voxel cache lives: --cache DIR, or --no-cache, or defaultCacheFolder().
struct CacheArgs {
    std::string folder;
    bool disabled = false;
    std::filesystem::path resolve() const;
};
void addCacheOptions(CLI::App* command, CacheArgs& args);

/// The scene's voxelized source and target through the cache, saying where they came from (on
/// stdout unless `quiet`; a rebuilt or unstorable entry always on stderr).
SceneVolumes loadSceneVolumes(const Scene& scene, const CacheArgs& cache, Interrupter& interrupter,
                              uint64_t memoryLimitBytes, bool quiet);

/// Progress of a sequence. On a terminal: a live bar with the ETA, redrawn in place. Otherwise
/// (a log, a render farm): one flushed line per update, `ALF_PROGRESS 42%`, which farm software
/// (Tractor, OpenCue, Deadline with a regex) parses.
class Progress {
public:
    Progress(int steps, bool quiet);
    /// Marks `done` of the steps finished.
    void update(int done);
    /// Prints a log line, keeping the bar below it on a terminal.
    void log(const std::string& line);
    /// Ends the bar's line (on a terminal).
    ~Progress();

private:
    int mSteps, mLastPercent = -1, mLastDone = 0;
    bool mQuiet, mTerminal, mBarShown = false;
    std::chrono::steady_clock::time_point mStart;
};

/// Routes SIGINT and SIGTERM to `interrupter` for the lifetime of this object.
class StopSignals {
public:
    explicit StopSignals(Interrupter& interrupter);
    ~StopSignals();

private:
    struct sigaction mOldInt {
    }, mOldTerm{};
};

} // namespace volmorph::cli
