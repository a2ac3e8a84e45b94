#include "FrameLoop.h"

#include <chrono>
#include <cstdio>

namespace volmorph::cli {

FrameLoop::FrameLoop(const Scene& scene, std::vector<int> frames, int stepsPerFrame, bool quiet,
                     bool logFrames, Interrupter& interrupter)
    : mScene(scene), mFrames(std::move(frames)), mSteps(stepsPerFrame), mLogFrames(logFrames),
      mInterrupter(interrupter), mProgress(stepsPerFrame * int(mFrames.size()), quiet)
{
}

int FrameLoop::run(const std::function<FrameResult(const FrameStep&)>& work)
{
    int failed = 0;
    mProgress.update(0);
    for (size_t i = 0; i < mFrames.size(); ++i) {
        const int base = mSteps * int(i);
        const FrameStep step{mFrames[i], mScene.frames.t(mFrames[i]), i,
                             [this, base](int k) { mProgress.update(base + k); }};
        const auto start = std::chrono::steady_clock::now();
        const FrameResult result = work(step);
        if (mInterrupter.stopRequested()) throw Interrupted();
        if (result.outcome == FrameResult::Outcome::Failed) ++failed;
        report(step, result, secondsSince(start));
        mProgress.update(base + mSteps);
    }
    if (failed) std::fprintf(stderr, "volmorph: %d of %zu frames failed\n", failed, mFrames.size());
    return failed;
}

void FrameLoop::report(const FrameStep& step, const FrameResult& result, double seconds)
{
    switch (result.outcome) {
    case FrameResult::Outcome::Failed:
        std::fprintf(stderr, "%s\n", result.detail.c_str());
        return;
    case FrameResult::Outcome::Skipped:
        mProgress.log(result.detail);
        return;
    case FrameResult::Outcome::Done:
        if (!mLogFrames) return;
        char line[1024];
        std::snprintf(line, sizeof line, "frame %d (t=%.4f): %s%s%.2f s -> %s", step.frame, step.t,
                      result.detail.c_str(), result.detail.empty() ? "" : ", ", seconds,
                      result.output.c_str());
        mProgress.log(line);
        return;
    }
}

} // namespace volmorph::cli
