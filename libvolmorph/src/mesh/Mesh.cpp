// Mesh import through Assimp, then clean-up and topology checks of our own.
//
// Assimp's JoinIdenticalVertices compares normals and texture coordinates too, so an STL file (one
// normal per face) would stay a soup of unconnected triangles. We weld on exact positions instead,
// which is what topology (holes, non-manifold edges, shells) is about. Assimp runs in a child
// process with a time limit (see readIsolated).
#include <volmorph/Mesh.h>

#include "mesh/DisjointSets.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace volmorph {
namespace {

struct PositionHash {
    size_t operator()(const Vec3f& p) const
    {
        // Positions are compared exactly; +0 and -0 are made equal by the caller.
        size_t h = 0;
        for (int i = 0; i < 3; ++i) {
            const float v = p[i];
            uint32_t bits;
            std::memcpy(&bits, &v, sizeof bits);
            h ^= std::hash<uint32_t>()(bits) + 0x9e3779b9 + (h << 6) + (h >> 2);
        }
        return h;
    }
};

SourceLocation errorPlace(const std::filesystem::path& file, const SourceLocation& where)
{
    return where.file.empty() ? SourceLocation{file.string()} : where;
}

std::string prefix(const std::filesystem::path& file, const SourceLocation& where)
{
    // When the error is reported at a scene key, the message still names the mesh file.
    return where.file.empty() ? std::string() : "mesh '" + file.string() + "': ";
}

} // namespace

std::pair<Vec3d, Vec3d> Mesh::bounds() const
{
    const double inf = std::numeric_limits<double>::infinity();
    Vec3d lo(inf), hi(-inf);
    for (const Vec3f& p : points) {
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], double(p[i]));
            hi[i] = std::max(hi[i], double(p[i]));
        }
    }
    return {lo, hi};
}

void analyzeTopology(Mesh& mesh)
{
    MeshReport& r = mesh.report;
    // Each undirected edge (a < b) counts its uses and how many times it is traversed a -> b.
    // A consistently oriented manifold edge is used twice, once in each direction.
    struct EdgeUse {
        uint32_t count = 0;
        uint32_t forward = 0;
    };
    std::unordered_map<uint64_t, EdgeUse> edges;
    edges.reserve(mesh.triangles.size() * 2);
    detail::DisjointSets sets(mesh.points.size());
    for (const Vec3I& tri : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = tri[k], b = tri[(k + 1) % 3];
            const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            EdgeUse& use = edges[key];
            ++use.count;
            if (a < b) ++use.forward;
            sets.unite(a, b);
        }
    }
    r.boundaryEdges = r.nonManifoldEdges = r.misorientedEdges = 0;
    for (const auto& [key, use] : edges) {
        if (use.count == 1)
            ++r.boundaryEdges;
        else if (use.count > 2)
            ++r.nonManifoldEdges;
        else if (use.forward != 1)
            ++r.misorientedEdges;
    }
    std::vector<char> used(mesh.points.size(), 0);
    for (const Vec3I& tri : mesh.triangles)
        for (int k = 0; k < 3; ++k) used[tri[k]] = 1;
    r.components = 0;
    for (uint32_t v = 0; v < mesh.points.size(); ++v)
        if (used[v] && sets.find(v) == v) ++r.components;
}

namespace {

/// What Assimp read: every placed mesh instance concatenated, with node transforms applied and
/// polygons split into fans. Indices are into `positions` (3 floats per vertex).
struct RawMesh {
    std::vector<float> positions, colors; ///< colors: 3 per vertex, or empty
    std::vector<float> uvs;               ///< 2 per vertex (Assimp splits seams), or empty
    std::vector<uint32_t> triangles;      ///< 3 per triangle
    std::string error;                    ///< set when the file could not be read
};

/// Assimp's reason for refusing a file, kept to one printable line of reasonable length (it may
/// quote the file).
std::string assimpError(const Assimp::Importer& importer)
{
    std::string why;
    for (const char c : std::string(importer.GetErrorString())) {
        if (why.size() >= 160) {
            why += "...";
            break;
        }
        why += (c >= 32 && c < 127) ? c : ' ';
    }
    return "cannot read mesh (" + (why.empty() ? std::string("unknown reason") : why) + ")";
}

/// Appends one mesh placed by `node`: its vertices (and colours, grey where it has none, when
/// `anyColors`), its polygons as fans (exact when convex); points and lines are of no use to a
/// voxelizer. Sets raw.error on a face that names a missing vertex.
void addMesh(RawMesh& raw, const aiMesh* am, const aiMatrix4x4& node, bool anyColors, bool anyUVs)
{
    const uint32_t base = uint32_t(raw.positions.size() / 3);
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
        const aiVector3D& a = am->mVertices[v];
        // A non-finite input stays non-finite (the transform could hide a NaN behind a 0 scale).
        const bool finite = std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
        const aiVector3D w =
            finite ? node * a : aiVector3D(std::numeric_limits<float>::quiet_NaN());
        raw.positions.insert(raw.positions.end(), {w.x, w.y, w.z});
        if (anyColors) {
            const aiColor4D c =
                am->HasVertexColors(0) ? am->mColors[0][v] : aiColor4D(0.8f, 0.8f, 0.8f, 1.0f);
            raw.colors.insert(raw.colors.end(), {c.r, c.g, c.b});
        }
        if (anyUVs) {
            const aiVector3D uv = am->HasTextureCoords(0) ? am->mTextureCoords[0][v] : aiVector3D();
            raw.uvs.insert(raw.uvs.end(), {uv.x, uv.y});
        }
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
        const aiFace& face = am->mFaces[f];
        if (face.mNumIndices < 3) continue;
        bool inRange = true;
        for (unsigned k = 0; k < face.mNumIndices; ++k)
            inRange = inRange && face.mIndices[k] < am->mNumVertices;
        if (!inRange) {
            raw.error = "face " + std::to_string(f + 1) + " names a vertex that does not exist";
            return;
        }
        for (unsigned k = 1; k + 1 < face.mNumIndices; ++k)
            raw.triangles.insert(
                raw.triangles.end(),
                {base + face.mIndices[0], base + face.mIndices[k], base + face.mIndices[k + 1]});
    }
}

/// Reads `file` with Assimp into a RawMesh (in whichever process calls it).
RawMesh readWithAssimp(const std::filesystem::path& file)
{
    RawMesh raw;
    Assimp::Importer importer;
    // Only validation: Assimp's own post-processing steps (Triangulate, PreTransformVertices,
    // SortByPType) abort the process on some malformed files (an ai_assert in TriangulateProcess,
    // found by fuzzing). Node transforms and polygon splitting are done here instead.
    const aiScene* scene = importer.ReadFile(file.string(), aiProcess_ValidateDataStructure);
    if (!scene) {
        raw.error = assimpError(importer);
        return raw;
    }
    if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) {
        raw.error = "the mesh file is incomplete or malformed";
        return raw;
    }
    bool anyColors = false, anyUVs = false;
    for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
        anyColors = anyColors || scene->mMeshes[mi]->HasVertexColors(0);
        anyUVs = anyUVs || scene->mMeshes[mi]->HasTextureCoords(0);
    }
    // Every mesh as often as the node hierarchy places it (what PreTransformVertices would do).
    std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack;
    if (scene->mRootNode) stack.emplace_back(scene->mRootNode, scene->mRootNode->mTransformation);
    size_t placed = 0;
    while (!stack.empty() && raw.error.empty()) {
        const auto [node, xf] = stack.back();
        stack.pop_back();
        for (unsigned i = 0; i < node->mNumMeshes; ++i)
            if (node->mMeshes[i] < scene->mNumMeshes) {
                addMesh(raw, scene->mMeshes[node->mMeshes[i]], xf, anyColors, anyUVs);
                ++placed;
            }
        if (stack.size() + node->mNumChildren > 100000) {
            raw.error = "the node hierarchy is too deep or too large";
            break;
        }
        for (unsigned c = 0; c < node->mNumChildren; ++c)
            stack.emplace_back(node->mChildren[c], xf * node->mChildren[c]->mTransformation);
    }
    if (placed == 0 && raw.error.empty()) // no node hierarchy: the meshes as stored
        for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi)
            addMesh(raw, scene->mMeshes[mi], aiMatrix4x4(), anyColors, anyUVs);
    return raw;
}

/// One ::read or ::write (`io`) of at most `size` bytes at p, retried when a signal interrupts
/// it; advances p and size. False on an error or the end of the file.
template <typename Io, typename Byte>
bool transfer(Io io, int fd, Byte*& p, size_t& size)
{
    ssize_t n;
    do {
        n = io(fd, p, size);
    } while (n < 0 && errno == EINTR);
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
    return true;
}

bool writeAll(int fd, const void* data, size_t size)
{
    const char* p = static_cast<const char*>(data);
    while (size > 0)
        if (!transfer(::write, fd, p, size)) return false;
    return true;
}

template <typename T>
bool writeVector(int fd, const std::vector<T>& v)
{
    const uint64_t n = v.size();
    return writeAll(fd, &n, sizeof n) && writeAll(fd, v.data(), v.size() * sizeof(T));
}

/// True when process `pid` is asleep (blocked, not waiting for a core): /proc/pid/stat's state.
bool asleep(pid_t pid)
{
    char path[64];
    std::snprintf(path, sizeof path, "/proc/%d/stat", int(pid));
    std::FILE* f = std::fopen(path, "r");
    if (!f) return false;
    char text[512];
    const size_t n = std::fread(text, 1, sizeof text - 1, f);
    std::fclose(f);
    text[n] = '\0';
    const char* close = std::strrchr(text, ')'); // the name may hold anything but this
    return close && close[1] == ' ' && close[2] == 'S';
}

/// How long the reader in the child may take: `cpuSeconds` of its own work (a parser in an endless
/// loop spends it) and at most `wallSeconds` of waiting. Work is measured, not the wall clock, so
/// that a child starved of a core on a loaded machine is not taken for a hung one. A child asleep
/// with no work done for kStallSeconds is stalled: fork() copies one thread of a process whose
/// other threads (TBB's) may hold a lock at that instant, and the child then waits for it forever
/// (seen: a sphere's import under ASan, and a cube's in CI; the caller forks again).
class ReaderBudget {
public:
    static constexpr double kStallSeconds = 2.0;

    ReaderBudget(pid_t child, double cpuSeconds, double wallSeconds)
        : mChild(child), mCpu(cpuSeconds), mWall(wallSeconds),
          mStart(std::chrono::steady_clock::now()), mLastWork(mStart)
    {
        mHasCpuClock = ::clock_getcpuclockid(child, &mClock) == 0;
    }

    /// True once a limit is spent or the child stalled; `exhausted()` then says which.
    bool spent()
    {
        const auto now = std::chrono::steady_clock::now();
        const double waited = std::chrono::duration<double>(now - mStart).count();
        timespec used{};
        const bool cpuKnown = mHasCpuClock && ::clock_gettime(mClock, &used) == 0;
        const double worked = cpuKnown ? double(used.tv_sec) + 1e-9 * double(used.tv_nsec) : waited;
        if (worked > mWorked) mWorked = worked, mLastWork = now;
        const double idle = std::chrono::duration<double>(now - mLastWork).count();
        if (worked >= mCpu)
            mExhausted = Limit::Cpu;
        else if (waited >= mWall)
            mExhausted = Limit::Wall;
        else if (cpuKnown && idle >= kStallSeconds && asleep(mChild))
            mExhausted = Limit::Stalled;
        return mExhausted != Limit::None;
    }

    enum class Limit { None, Cpu, Wall, Stalled };
    Limit exhausted() const { return mExhausted; }
    double cpuSeconds() const { return mCpu; }
    double wallSeconds() const { return mWall; }

private:
    pid_t mChild;
    double mCpu, mWall, mWorked = -1.0;
    std::chrono::steady_clock::time_point mStart, mLastWork;
    clockid_t mClock{};
    bool mHasCpuClock = false;
    Limit mExhausted = Limit::None;
};

/// Reads exactly `size` bytes while `budget` lasts; false on EOF, error or a spent budget.
bool readAll(int fd, void* data, size_t size, ReaderBudget& budget)
{
    char* p = static_cast<char*>(data);
    while (size > 0) {
        if (budget.spent()) return false;
        pollfd pfd{fd, POLLIN, 0};
        const int r = ::poll(&pfd, 1, 100);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return false;
        if (r == 0) continue;
        if (!transfer(::read, fd, p, size)) return false;
    }
    return true;
}

template <typename T>
bool readVector(int fd, std::vector<T>& v, ReaderBudget& budget)
{
    uint64_t n = 0;
    if (!readAll(fd, &n, sizeof n, budget) || n > (uint64_t(1) << 34) / sizeof(T)) return false;
    v.resize(size_t(n));
    return readAll(fd, v.data(), v.size() * sizeof(T), budget);
}

/// readWithAssimp() in a child process, so that a parser that aborts, crashes or never returns on
/// a malformed file (Assimp 5.2 does all three; fuzzing found them) becomes an error message, not
/// a dead or hung volmorph; a child that stalled (ReaderBudget) is tried again, three times in
/// all. The limits grow with the file: 2 s of the reader's CPU time plus 1 s per MB (Assimp reads
/// tens of MB a second; a parser in an endless loop is stopped within the 10 s a bad input may
/// take even with a third of a core), and 60 s plus 10 s per MB of waiting.
RawMesh readInChild(const std::filesystem::path& file, uintmax_t bytes, bool& stalled)
{
    RawMesh raw;
    int fds[2];
    if (::pipe(fds) != 0) return readWithAssimp(file);
    std::fflush(nullptr);
    const pid_t child = ::fork();
    if (child < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        return readWithAssimp(file);
    }
    if (child == 0) {
        ::close(fds[0]);
        const RawMesh r = readWithAssimp(file);
        const bool ok = writeVector(fds[1], std::vector<char>(r.error.begin(), r.error.end())) &&
                        writeVector(fds[1], r.positions) && writeVector(fds[1], r.colors) &&
                        writeVector(fds[1], r.uvs) && writeVector(fds[1], r.triangles);
        ::_exit(ok ? 0 : 1);
    }
    ::close(fds[1]);
    ReaderBudget budget(child, 2.0 + 1.0 * double(bytes) / 1e6, 60.0 + 10.0 * double(bytes) / 1e6);
    std::vector<char> error;
    const bool ok = readVector(fds[0], error, budget) &&
                    readVector(fds[0], raw.positions, budget) &&
                    readVector(fds[0], raw.colors, budget) && readVector(fds[0], raw.uvs, budget) &&
                    readVector(fds[0], raw.triangles, budget);
    ::close(fds[0]);
    if (!ok) ::kill(child, SIGKILL);
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {}
    if (ok) {
        raw.error.assign(error.begin(), error.end());
        return raw;
    }
    raw = RawMesh{};
    stalled = budget.exhausted() == ReaderBudget::Limit::Stalled;
    if (stalled) {
        raw.error = "the mesh reader stopped working three times (a fork of a busy process)";
    } else if (budget.exhausted() != ReaderBudget::Limit::None) {
        const bool cpu = budget.exhausted() == ReaderBudget::Limit::Cpu;
        char text[200];
        std::snprintf(text, sizeof text,
                      cpu ? "the mesh reader did not finish within %.0f s of work; the file is "
                            "probably malformed"
                          : "the mesh reader did not finish within %.0f s (it stopped working); "
                            "the file is probably malformed",
                      cpu ? budget.cpuSeconds() : budget.wallSeconds());
        raw.error = text;
    } else if (WIFSIGNALED(status)) {
        raw.error = "the mesh reader (Assimp) crashed on this file (signal " +
                    std::to_string(WTERMSIG(status)) + "); the file is probably malformed";
    } else {
        raw.error = "the mesh reader (Assimp) failed on this file; it is probably malformed";
    }
    return raw;
}

RawMesh readIsolated(const std::filesystem::path& file, uintmax_t bytes)
{
    for (int attempt = 1;; ++attempt) {
        bool stalled = false;
        RawMesh raw = readInChild(file, bytes, stalled);
        if (!stalled || attempt == 3) return raw;
    }
}

} // namespace

Mesh importMesh(const std::filesystem::path& file, const ObjectTransform& transform,
                const SourceLocation& where)
{
    const SourceLocation place = errorPlace(file, where);
    const std::string pre = prefix(file, where);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        throw UserError(
            {{place, pre + "mesh file not found or not a regular file", file.string()}});
    const uintmax_t bytes = std::filesystem::file_size(file, ec);
    if (bytes == 0) throw UserError(place, pre + "mesh file is empty");

    const RawMesh raw = readIsolated(file, bytes);
    if (!raw.error.empty()) throw UserError(place, pre + raw.error);

    Mesh mesh;
    mesh.file = file;
    const Mat4d m = transform.matrix();
    std::unordered_map<Vec3f, uint32_t, PositionHash> index;
    const size_t vertices = raw.positions.size() / 3;
    const bool anyColors = raw.colors.size() == raw.positions.size() && !raw.colors.empty();
    const bool anyUVs = raw.uvs.size() == 2 * vertices && !raw.uvs.empty();
    std::vector<uint32_t> remap(vertices, 0);
    for (size_t v = 0; v < vertices; ++v) {
        const float* a = &raw.positions[3 * v];
        if (!std::isfinite(a[0]) || !std::isfinite(a[1]) || !std::isfinite(a[2]))
            throw UserError(place, pre + "vertex " + std::to_string(v + 1) +
                                       " has a non-finite coordinate (NaN or inf)");
        const Vec3d w = m.transform(Vec3d(a[0], a[1], a[2]));
        Vec3f p(float(w.x()) + 0.0f, float(w.y()) + 0.0f, float(w.z()) + 0.0f); // -0 -> +0
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
            throw UserError(place, pre + "vertex " + std::to_string(v + 1) +
                                       " is out of range after the transform");
        const auto [it, inserted] = index.try_emplace(p, uint32_t(mesh.points.size()));
        if (inserted) {
            mesh.points.push_back(p);
            if (anyColors)
                mesh.colors.emplace_back(raw.colors[3 * v], raw.colors[3 * v + 1],
                                         raw.colors[3 * v + 2]);
        } else {
            ++mesh.report.duplicateVertices;
        }
        remap[v] = it->second;
    }
    for (size_t t = 0; t + 2 < raw.triangles.size(); t += 3) {
        ++mesh.report.inputTriangles;
        if (raw.triangles[t] >= vertices || raw.triangles[t + 1] >= vertices ||
            raw.triangles[t + 2] >= vertices)
            throw UserError(place, pre + "a face names a vertex that does not exist");
        const Vec3I tri(remap[raw.triangles[t]], remap[raw.triangles[t + 1]],
                        remap[raw.triangles[t + 2]]);
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
            ++mesh.report.degenerateTriangles;
            continue;
        }
        const Vec3d a(mesh.points[tri[0]]), b(mesh.points[tri[1]]), c(mesh.points[tri[2]]);
        if ((b - a).cross(c - a).lengthSqr() == 0.0) {
            ++mesh.report.degenerateTriangles;
            continue;
        }
        mesh.triangles.push_back(tri);
        if (anyUVs)
            for (int c = 0; c < 3; ++c) {
                const size_t v = raw.triangles[t + size_t(c)];
                mesh.uvs.emplace_back(raw.uvs[2 * v], raw.uvs[2 * v + 1]);
            }
    }
    if (mesh.report.inputTriangles == 0) throw UserError(place, pre + "the mesh has no triangles");
    if (mesh.triangles.empty())
        throw UserError(place, pre + "every one of the mesh's " +
                                   std::to_string(mesh.report.inputTriangles) +
                                   " triangles is degenerate (zero area)");
    analyzeTopology(mesh);
    return mesh;
}

} // namespace volmorph
