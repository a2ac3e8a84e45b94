// Progress and cancellation for long operations, in OpenVDB's interrupter form (start, end,
// wasInterrupted(percent)) so the same object drives OpenVDB's tools and volmorph's own loops.
#pragma once

#include <openvdb/util/NullInterrupter.h>

#include <atomic>
#include <chrono>
#include <string>

namespace volmorph {

/// Cancels when requestStop() is called (e.g. from a SIGINT handler: it is async-signal-safe)
/// and optionally prints progress to stderr: with `reportProgress` each operation's percentage,
/// with `logStages` one line per operation as it starts ("volmorph: 1.25 s  render: shadows",
/// seconds since the interrupter was made), to show a farm log or a user where the time goes.
class Interrupter : public openvdb::util::NullInterrupter {
public:
    explicit Interrupter(bool reportProgress = false, bool logStages = false)
        : mReport(reportProgress), mLogStages(logStages), mCreated(std::chrono::steady_clock::now())
    {
    }

    void start(const char* name = nullptr) override;
    void end() override;
    bool wasInterrupted(int percent = -1) override;

    /// Async-signal-safe: only stores to a lock-free atomic.
    void requestStop() { mStop.store(true, std::memory_order_relaxed); }
    bool stopRequested() const { return mStop.load(std::memory_order_relaxed); }

private:
    bool mReport, mLogStages;
    std::chrono::steady_clock::time_point mCreated;
    std::string mName;
    std::atomic<int> mLastPercent{-1};
    std::atomic<bool> mStop{false};
};

/// Thrown by volmorph's own code when an Interrupter asked to stop.
struct Interrupted : std::exception {
    const char* what() const noexcept override { return "interrupted"; }
};

/// Work abandoned on a stop request (blend/Abandonable.h: an OpenVDB tool or a dense solve that
/// takes no interrupter, left to finish on its own thread) and still running. While it runs, the
/// process must not run its static destructors (OpenVDB's and TBB's state is still in use there):
/// a program that caught Interrupted ends with std::_Exit when this is not zero.
int abandonedWorkRunning();

namespace detail {
/// Abandonable's bookkeeping: +1 when work is abandoned, -1 when its thread is done with it.
void countAbandonedWork(int change);
} // namespace detail

/// Throws Interrupted when `interrupter` (may be null) asks to stop; `percent` is the progress.
inline void throwIfInterrupted(Interrupter* interrupter, int percent = -1)
{
    if (interrupter && interrupter->wasInterrupted(percent)) throw Interrupted();
}

} // namespace volmorph
