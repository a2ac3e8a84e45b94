// A surface morph's frame as binary PLY with each vertex's velocity (vx vy vz), or as OBJ. Written
// here, not through Assimp: its exporter has no vertex properties of a program's own.
#include <volmorph/Export.h>

#include <volmorph/core/AtomicFile.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace volmorph {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "PLY bytes are written in host order");

template <typename T>
void put(std::string& out, T value)
{
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

uint8_t byteOf(float linear) // Assimp's PLY convention: linear values times 255
{
    return uint8_t(std::lround(std::clamp(linear, 0.0f, 1.0f) * 255.0f));
}

std::string plyBytes(const SurfaceFrame& frame)
{
    const bool colors = !frame.colors.empty();
    std::string out = "ply\nformat binary_little_endian 1.0\ncomment volmorph surface morph: "
                      "vx vy vz in world units per second\nelement vertex " +
                      std::to_string(frame.points.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "property float vx\nproperty float vy\nproperty float vz\n";
    if (colors)
        out += "property uchar red\nproperty uchar green\nproperty uchar blue\n"
               "property uchar alpha\n";
    out += "element face " + std::to_string(frame.triangles.size()) +
           "\nproperty list uchar int vertex_indices\nend_header\n";
    out.reserve(out.size() + frame.points.size() * 28 + frame.triangles.size() * 13);
    for (size_t i = 0; i < frame.points.size(); ++i) {
        for (int c = 0; c < 3; ++c) put(out, float(frame.points[i][c]));
        for (int c = 0; c < 3; ++c)
            put(out, i < frame.velocity.size() ? float(frame.velocity[i][c]) : 0.0f);
        if (colors) {
            for (int c = 0; c < 3; ++c) put(out, byteOf(frame.colors[i][c]));
            put(out, uint8_t(255));
        }
    }
    for (const Vec3I& t : frame.triangles) {
        put(out, uint8_t(3));
        for (int c = 0; c < 3; ++c) put(out, int32_t(t[c]));
    }
    return out;
}

} // namespace

void writeSurfaceFrame(const SurfaceFrame& frame, const std::filesystem::path& path)
{
    const std::string ext = path.extension().string();
    if (ext == ".obj") {
        writeMesh(frame.mesh(), path);
        return;
    }
    if (ext != ".ply")
        throw UserError(SourceLocation{path.string()},
                        "expected a mesh file name ending in .ply or .obj");
    const std::string bytes = plyBytes(frame);
    writeAtomically(path, "mesh", [&](const std::filesystem::path& temporary) {
        std::ofstream file(temporary, std::ios::binary);
        file.write(bytes.data(), std::streamsize(bytes.size()));
        file.close();
        if (!file) throw std::runtime_error("write failed");
    });
}

} // namespace volmorph
