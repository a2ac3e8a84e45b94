// libFuzzer target: the scene parser. Any input must give a Scene or a UserError listing its
// problems; a crash, a sanitizer report, a hang or any other exception is a bug.
#include <volmorph/core/Diagnostics.h>
#include <volmorph/Scene.h>

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        // Relative mesh paths resolve against this (non-existent) folder: they are reported
        // missing.
        volmorph::parseScene(text, "/nonexistent/fuzz/scene.toml");
    } catch (const volmorph::UserError&) {
    }
    return 0;
}
