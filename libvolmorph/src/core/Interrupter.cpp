#include <volmorph/Interrupter.h>

#include <cstdio>

namespace volmorph {

void Interrupter::start(const char* name)
{
    mName = name ? name : "";
    mLastPercent = -1;
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
