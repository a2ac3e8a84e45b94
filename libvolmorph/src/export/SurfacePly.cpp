// A surface morph's frame as binary PLY with each vertex's velocity (vx vy vz), or as OBJ. Written
// here, not through Assimp: its exporter has no vertex properties of a program's own, and keeps
// texture coordinates per vertex, where a frame has them per triangle corner (a seam's vertex has
// one place and two sets of coordinates). PLY holds them as MeshLab's per-face `texcoord` list (at
// the frame's tau) and, for blending two textures, `texcoord_source` and `texcoord_target`; OBJ as
// `vt` lines at the frame's tau.
#include <volmorph/Export.h>

#include <volmorph/core/AtomicFile.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
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
    const bool uvs = frame.uvs.size() == 3 * frame.triangles.size() && !frame.uvs.empty();
    out += "element face " + std::to_string(frame.triangles.size()) +
           "\nproperty list uchar int vertex_indices\n";
    if (uvs)
        out += "property list uchar float texcoord\nproperty list uchar float texcoord_source\n"
               "property list uchar float texcoord_target\n";
    out += "end_header\n";
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
    for (size_t j = 0; j < frame.triangles.size(); ++j) {
        put(out, uint8_t(3));
        for (int c = 0; c < 3; ++c) put(out, int32_t(frame.triangles[j][c]));
        if (!uvs) continue;
        for (const std::vector<Vec2f>* set : {&frame.uvs, &frame.sourceUVs, &frame.targetUVs}) {
            put(out, uint8_t(6));
            for (size_t c = 0; c < 3; ++c) {
                put(out, float((*set)[3 * j + c].x()));
                put(out, float((*set)[3 * j + c].y()));
            }
        }
    }
    return out;
}

/// OBJ text with a `vt` per triangle corner (at the frame's tau).
std::string objText(const SurfaceFrame& frame)
{
    std::ostringstream os;
    os.precision(9);
    os << "# volmorph surface morph\n";
    for (const Vec3d& p : frame.points)
        os << "v " << float(p.x()) << ' ' << float(p.y()) << ' ' << float(p.z()) << '\n';
    for (const Vec2f& uv : frame.uvs) os << "vt " << uv.x() << ' ' << uv.y() << '\n';
    for (size_t j = 0; j < frame.triangles.size(); ++j) {
        os << 'f';
        for (size_t c = 0; c < 3; ++c)
            os << ' ' << frame.triangles[j][c] + 1 << '/' << 3 * j + c + 1;
        os << '\n';
    }
    return os.str();
}

void writeBytes(const std::filesystem::path& path, const std::string& bytes)
{
    writeAtomically(path, "mesh", [&](const std::filesystem::path& temporary) {
        std::ofstream file(temporary, std::ios::binary);
        file.write(bytes.data(), std::streamsize(bytes.size()));
        file.close();
        if (!file) throw std::runtime_error("write failed");
    });
}

} // namespace

void writeSurfaceFrame(const SurfaceFrame& frame, const std::filesystem::path& path)
{
    const std::string ext = path.extension().string();
    if (ext == ".obj" && frame.uvs.empty()) {
        writeMesh(frame.mesh(), path);
        return;
    }
    if (ext == ".obj") {
        writeBytes(path, objText(frame));
        return;
    }
    if (ext != ".ply")
        throw UserError(SourceLocation{path.string()},
                        "expected a mesh file name ending in .ply or .obj");
    writeBytes(path, plyBytes(frame));
}

} // namespace volmorph
