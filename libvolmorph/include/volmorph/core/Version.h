#pragma once

namespace volmorph {

/// "MAJOR.MINOR.PATCH" of this build (from the top-level CMake project version).
const char* versionString();

} // namespace volmorph
