// Shared pieces of the volmorph subcommands: exit codes, number formatting, stop signals.
#pragma once

#include <volmorph/Interrupter.h>
#include <volmorph/Mesh.h>

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

std::string fmt(double v);
std::string fmt(const Vec3d& v);
std::string describeTopology(const MeshReport& r);

/// Wall-clock seconds since `start`.
double secondsSince(std::chrono::steady_clock::time_point start);

/// Routes SIGINT and SIGTERM to `interrupter` for the lifetime of this object.
class StopSignals {
public:
    explicit StopSignals(Interrupter& interrupter);
    ~StopSignals();

private:
    struct sigaction mOldInt {}, mOldTerm {};
};

} // namespace volmorph::cli
