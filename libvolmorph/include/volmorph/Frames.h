// Frame specs and output file patterns, as VFX tools write them.
#pragma once

#include <volmorph/Scene.h>

#include <string>
#include <vector>

namespace volmorph {

/// Frames picked by `spec` in OpenImageIO's sequence syntax ("1-10", "1-100x2", "1,5,10-20"),
/// in the order given and without repeats; every one must lie in the scene's range (their t comes
/// from that range, so a chunk renders exactly the frames a full run would). An empty spec picks
/// the whole range. Throws UserError naming `what` (the front end's name for the spec) when the
/// spec is malformed, empty or outside the range.
std::vector<int> selectFrames(const FramesSpec& frames, const std::string& spec,
                              const std::string& what = "frames");

/// `frames` written as a frame spec, consecutive runs as ranges: {1,2,3,5,7,8} -> "1-3,5,7-8".
std::string formatFrames(const std::vector<int>& frames);

/// The frames of chunk `index` (0-based) when `frames` are cut into chunks of `chunkSize` in order;
/// the last chunk takes the remainder. chunkCount() gives how many there are.
std::vector<int> chunkFrames(const std::vector<int>& frames, int chunkSize, int index);
int chunkCount(const std::vector<int>& frames, int chunkSize);

/// Checks a pattern's frame placeholder: one run of N '#' (the frame zero-padded to N digits:
/// #### -> 0042), or a printf %d / %0Nd. Returns an empty string when valid, else why not.
std::string checkFramePattern(const std::string& pattern);

/// Whether `pattern` has a frame placeholder (#### or %0Nd).
bool hasFramePlaceholder(const std::string& pattern);

/// The frame numbers of the files on disk that `pattern` names (OpenImageIO's directory scan),
/// sorted; empty when there are none or the folder does not exist.
std::vector<int> sequenceFrames(const std::string& pattern);

/// The file name of `frame` under `pattern` (a pattern without placeholder names one file).
std::string frameFileName(const std::string& pattern, int frame);

} // namespace volmorph
