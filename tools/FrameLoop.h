// The loop over a sequence's frames that `morph`, `render` and `preview` share: frames in order,
// progress (a bar on a terminal, ALF_PROGRESS lines for a farm), a timing line per frame, a stop as
// soon as the interrupter asks, and frames that failed counted, not fatal.
#pragma once

#include "Common.h"

#include <volmorph/Scene.h>

#include <functional>
#include <string>
#include <vector>

namespace volmorph::cli {

/// What one frame's work says about it.
struct FrameResult {
    enum class Outcome { Done, Skipped, Failed };
    Outcome outcome = Outcome::Done;
    /// Done: what the frame line says before the time (e.g. "4981701 active voxels"), may be empty.
    /// Skipped: the whole line. Failed: the error, printed on stderr.
    std::string detail;
    std::string output; ///< Done: the file written, if any
};

/// One frame being worked on.
struct FrameStep {
    int frame;
    double t;
    size_t index; ///< position in the sequence
    /// Marks `k` of the frame's `stepsPerFrame` steps done (progress within long frames).
    std::function<void(int k)> progress;
};

class FrameLoop {
public:
    /// `stepsPerFrame`: how many progress steps one frame counts (e.g. morph and render: 2).
    /// `logFrames`: print a line per frame ("frame 3 (t=0.0870): 1.52 s -> out.0003.exr").
    FrameLoop(const Scene& scene, std::vector<int> frames, int stepsPerFrame, bool quiet,
              bool logFrames, Interrupter& interrupter);

    /// Calls `work` for each frame in order. Throws Interrupted as soon as the interrupter asked
    /// to stop (after the frame at work). Returns the number of frames whose work failed.
    int run(const std::function<FrameResult(const FrameStep&)>& work);

private:
    void report(const FrameStep& step, const FrameResult& result, double seconds);

    const Scene& mScene;
    std::vector<int> mFrames;
    int mSteps;
    bool mLogFrames;
    Interrupter& mInterrupter;
    Progress mProgress;
};

} // namespace volmorph::cli
