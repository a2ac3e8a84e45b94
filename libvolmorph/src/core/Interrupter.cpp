#include <volmorph/core/Interrupter.h>

#include <cstdio>

namespace volmorph {
namespace {
std::atomic<int> gAbandoned{0};
} // namespace

int abandonedWorkRunning()
{
    return gAbandoned.load();
}

void detail::countAbandonedWork(int change)
{
    gAbandoned += change;
}

void Interrupter::start(const char* name)
{
    mName = name ? name : "";
    mLastPercent = -1;
    if (mLogStages && !mName.empty()) {
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - mCreated).count();
        std::fprintf(stderr, "volmorph: %7.2f s  %s\n", seconds, mName.c_str());
        std::fflush(stderr);
    }
}

void Interrupter::end()
{
    if (mReport && mLastPercent >= 0) std::fprintf(stderr, "\r%s: 100%%\n", mName.c_str());
    mLastPercent = -1;
}

bool Interrupter::wasInterrupted(int percent)
{
    // Called from many threads; only whole-percent changes are printed.
    if (mReport && percent >= 0) {
        int last = mLastPercent.load(std::memory_order_relaxed);
        if (percent > last && mLastPercent.compare_exchange_strong(last, percent)) {
            std::fprintf(stderr, "\r%s: %3d%%", mName.c_str(), percent);
            std::fflush(stderr);
        }
    }
    return stopRequested();
}

} // namespace volmorph
