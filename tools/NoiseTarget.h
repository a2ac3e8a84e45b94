// The noise target on the command line: the --noise flag, and what a frame's line says of the
// samples it took and the noise it reached.
#pragma once

#include <volmorph/render/Renderer.h>

#include <CLI/CLI.hpp>

#include <string>

namespace volmorph::cli {

/// "16 samples, noise 0.0123" or, under a noise target, "87.3 samples per pixel of at most 1024,
/// noise 0.0098 (target 0.01)".
std::string samplesAndNoise(const render::Image& image, int samples, double target);

/// Adds --noise to `sub`: a target from 0 to 1 into `noise` (NaN refused: CLI11's ranges let it
/// through).
void addNoiseOption(CLI::App* sub, double& noise);

} // namespace volmorph::cli
