// libFuzzer target: mesh import (Assimp, then welding, degenerate-triangle removal, topology).
// The first byte picks the file extension, the rest is the file. Any input must give a Mesh or a
// UserError naming the file; a crash, a sanitizer report, a hang or any other exception is a bug.
#include <volmorph/core/Diagnostics.h>
#include <volmorph/Mesh.h>

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size < 1) return 0;
    static const char* const kExtensions[] = {".obj", ".ply", ".stl", ".off", ".gltf"};
    const std::string ext = kExtensions[data[0] % 5];
    static const std::filesystem::path dir = [] {
        const std::filesystem::path d =
            std::filesystem::temp_directory_path() / ("volmorph-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    const std::filesystem::path file = dir / ("input" + ext);
    if (FILE* f = std::fopen(file.c_str(), "wb")) {
        std::fwrite(data + 1, 1, size - 1, f);
        std::fclose(f);
    } else {
        return 0;
    }
    try {
        volmorph::importMesh(file);
    } catch (const volmorph::UserError&) {
    }
    std::filesystem::remove(file);
    return 0;
}
