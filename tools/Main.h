// The volmorph program is two executables with one command line (ARCHITECTURE.md, tools/):
// bin/volmorph runs the commands that write no image (voxelize, morph, cache, frames, pairs, edit),
// linked without the image libraries (OpenImageIO's codecs, Embree: about 260 shared libraries,
// most of a command's start-up); every other command line it hands, by exec, to
// libexec/volmorph/volmorph-image, which has every command.
#pragma once

#include "Common.h"

#include <vector>

namespace volmorph::cli {

/// Adds the image commands (check, render-vdb, render, diff, preview) to `app` and `commands`.
using AddCommands = void (*)(CLI::App& app, std::vector<Command>& commands);

/// Parses argv, runs the chosen subcommand and returns the exit status; every exception becomes
/// its status and a message on stderr. The commands are the light ones, and the image ones when
/// `addImageCommands` is given.
int runVolmorph(int argc, char** argv, AddCommands addImageCommands);

/// The light commands' names: what bin/volmorph runs itself.
inline constexpr const char* kLightCommands[] = {"voxelize", "morph", "cache",
                                                 "frames",   "pairs", "edit"};

} // namespace volmorph::cli
