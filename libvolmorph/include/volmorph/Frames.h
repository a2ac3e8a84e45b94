// Frame specs and output file patterns, as VFX tools write them.
#pragma once

#include <volmorph/Scene.h>

#include <string>
#include <vector>

namespace volmorph {

/// Frames picked by `spec` in OpenImageIO's sequence syntax ("1-10", "1-100x2", "1,5,10-20"),
/// in the order given and without repeats; every one must lie in the scene's range (their t comes
/// from that range, so a chunk renders exactly the frames a full run would). An empty spec picks
/// the whole range. Throws UserError naming `what` (e.g. "--frames") when the spec is malformed,
/// empty or outside the range.
std::vector<int> selectFrames(const FramesSpec& frames, const std::string& spec,
                              const std::string& what = "--frames");

/// Checks a pattern's frame placeholder: one run of N '#' (the frame zero-padded to N digits:
/// #### -> 0042), or a printf %d / %0Nd. Returns an empty string when valid, else why not.
std::string checkFramePattern(const std::string& pattern);

/// The file name of `frame` under `pattern` (a pattern without placeholder names one file).
std::string frameFileName(const std::string& pattern, int frame);

} // namespace volmorph
