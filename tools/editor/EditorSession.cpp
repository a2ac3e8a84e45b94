#include "EditorSession.h"

#include <volmorph/PairSuggest.h>
#include <volmorph/SceneSurface.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/Schedule.h>
#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Interrupter.h>

#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace volmorph::editor {
namespace {

using nlohmann::json;

template <typename T>
void put(std::string& out, const T& value)
{
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

Reply error(int status, const std::string& message)
{
    return {status, "application/json", json{{"error", message}}.dump()};
}

Reply stateReply(const EditDocument& document)
{
    return {200, "application/json", document.state().dump()};
}

/// The request's JSON body; an empty body is {}.
json parseBody(const std::string& body)
{
    if (body.empty()) return json::object();
    json value = json::parse(body, nullptr, false);
    if (value.is_discarded()) throw BadRequest("malformed JSON");
    return value;
}

/// Each point's delay under `timing`, for the page's colours; null when there is no timing.
template <typename Point>
std::unique_ptr<std::vector<float>> delaysOf(const std::vector<Point>& points,
                                             const LocalTime* timing)
{
    if (!timing || !timing->active()) return nullptr;
    auto delays = std::make_unique<std::vector<float>>(points.size());
    for (size_t i = 0; i < points.size(); ++i)
        (*delays)[i] = float(timing->delay(Vec3d(points[i])).d);
    return delays;
}

/// The timing an in-between is made under: `current` while the scene's timing is at the version
/// it was made for, else a new one from `timing` (the sweep was dragged) and the regions read once.
std::shared_ptr<const LocalTime> timingAt(std::shared_ptr<const LocalTime> current, bool changed,
                                          const TimingSettings& timing,
                                          const std::vector<TimingRegion>& regions)
{
    if (!changed) return current;
    return timing.spread > 0.0 ? std::make_shared<const LocalTime>(timing, regions) : nullptr;
}

} // namespace

std::string encodeMesh(const std::vector<openvdb::Vec3s>& points,
                       const std::vector<openvdb::Vec3I>& triangles,
                       const std::vector<openvdb::Vec4I>& quads, const std::vector<float>* delays)
{
    static_assert(sizeof(float) == 4 && sizeof(uint32_t) == 4, "32-bit floats and indices");
    openvdb::Vec3s lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const openvdb::Vec3s& p : points) lo = minComponent(lo, p), hi = maxComponent(hi, p);
    if (points.empty()) lo = hi = openvdb::Vec3s(0.0f);
    const uint32_t triangleCount = uint32_t(triangles.size() + 2 * quads.size());
    std::string out = delays ? "VMM2" : "VMM1";
    out.reserve(32 + points.size() * 6 + 4 + size_t(triangleCount) * 12);
    put(out, uint32_t(points.size()));
    put(out, triangleCount);
    for (int i = 0; i < 3; ++i) put(out, lo[i]);
    for (int i = 0; i < 3; ++i) put(out, hi[i]);
    for (const openvdb::Vec3s& p : points)
        for (int i = 0; i < 3; ++i) {
            const float extent = hi[i] - lo[i];
            const float u = extent > 0.0f ? (p[i] - lo[i]) / extent : 0.0f;
            put(out, uint16_t(std::lround(std::clamp(u, 0.0f, 1.0f) * 65535.0f)));
        }
    while (out.size() % 4) out.push_back('\0');
    // volumeToMesh winds its faces the other way from three.js's front faces.
    for (const openvdb::Vec3I& t : triangles) put(out, t[0]), put(out, t[2]), put(out, t[1]);
    for (const openvdb::Vec4I& q : quads) {
        put(out, q[0]), put(out, q[2]), put(out, q[1]);
        put(out, q[0]), put(out, q[3]), put(out, q[2]);
    }
    if (delays)
        for (size_t i = 0; i < points.size(); ++i)
            put(out, i < delays->size() ? (*delays)[i] : 0.0f);
    return out;
}

std::string surfaceOf(const VolumeSet& volumes, const LocalTime* timing)
{
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    if (volumes.sdf)
        openvdb::tools::volumeToMesh(*volumes.sdf, points, triangles, quads, 0.0, 0.0);
    else if (volumes.density)
        openvdb::tools::volumeToMesh(*volumes.density, points, triangles, quads, 0.5, 0.0);
    return encodeMesh(points, triangles, quads, delaysOf(points, timing).get());
}

std::string encodeTriangles(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                            const LocalTime* timing)
{
    std::vector<openvdb::Vec3s> p(points.begin(), points.end());
    // encodeMesh turns volumeToMesh's winding round: turned here first, the file's is kept.
    std::vector<openvdb::Vec3I> t;
    t.reserve(triangles.size());
    for (const Vec3I& f : triangles) t.emplace_back(f[0], f[2], f[1]);
    return encodeMesh(p, t, {}, delaysOf(points, timing).get());
}

EditorSession::EditorSession(const std::filesystem::path& scene, int resolution,
                             Interrupter* interrupter)
    : mInterrupter(interrupter), mDocument(scene)
{
    Scene preview = mDocument.scene();
    if (preview.blend.mode == BlendMode::Surface) { // the meshes as they are
        SceneMeshes meshes = importSceneMeshes(preview);
        const auto encode = [](const Mesh& m) {
            return encodeTriangles(std::vector<Vec3d>(m.points.begin(), m.points.end()),
                                   m.triangles);
        };
        mSourceMesh = encode(meshes.source);
        mTargetMesh = encode(meshes.target);
        if (preview.timing.spread > 0.0) { // its regions at the voxel size a morph would take
            const auto extent = [](const Mesh& m) {
                const auto [lo, hi] = m.bounds();
                return SideExtent{lo, hi, std::nullopt};
            };
            mTimingRegions = loadTimingRegions(
                preview,
                sceneVoxelSize(preview.volume, extent(meshes.source), extent(meshes.target)),
                interrupter);
            mLocalTime = std::make_shared<const LocalTime>(preview.timing, mTimingRegions);
        }
        mMorpherTiming = mDocument.timingVersion();
        mSurfaceSides.emplace(std::move(meshes.source), std::move(meshes.target));
        return;
    }
    preview.volume.voxelSize.reset();
    preview.volume.resolution = resolution;
    SceneVolumes volumes = voxelizeScene(preview, interrupter);
    mSource = std::move(volumes.source);
    mTarget = std::move(volumes.target);
    mInfluences = std::move(volumes.influences);
    mTimingRegions = std::move(volumes.timingRegions);
    if (preview.timing.spread > 0.0)
        mLocalTime = std::make_shared<const LocalTime>(preview.timing, mTimingRegions);
    mMorpherTiming = mDocument.timingVersion();
    mSourceMesh = surfaceOf(mSource);
    mTargetMesh = surfaceOf(mTarget);
}

EditorSession::~EditorSession() = default;

Reply EditorSession::sideMesh(const std::map<std::string, std::string>& query)
{
    const auto of = query.find("of");
    const std::string which = of == query.end() ? "" : of->second;
    if (which == "source" || which == "target")
        return {200, "application/octet-stream", which == "source" ? mSourceMesh : mTargetMesh};
    if (which != "morph") throw BadRequest("mesh: expected of=source, target or morph");
    const auto tText = query.find("t");
    char* end = nullptr;
    const double t = tText == query.end() ? 0.5 : std::strtod(tText->second.c_str(), &end);
    if (tText != query.end() && (end == tText->second.c_str() || *end != '\0'))
        throw BadRequest("mesh: t is not a number");
    if (!(t >= 0.0 && t <= 1.0)) throw BadRequest("mesh: t must lie in [0, 1]");
    return morphMesh(t);
}

Reply EditorSession::morphMesh(double t)
{
    if (mSurfaceSides) return surfaceMesh(t);
    std::lock_guard<std::mutex> one(mMorphMutex);
    std::shared_ptr<const Morpher> last;
    std::shared_ptr<const LocalTime> local;
    std::vector<FeaturePairSpec> pairs;
    WarpSpec warp;
    BlendSpec blend;
    TimingSettings timing;
    uint64_t version = 0, lastVersion = 0, timingVersion = 0, lastTiming = 0;
    {
        std::lock_guard<std::mutex> lock(mMutex);
        version = mDocument.pairsVersion();
        timingVersion = mDocument.timingVersion();
        if (mMorphVersion == version + timingVersion && mMorphT == t)
            return {200, "application/octet-stream", mMorphMesh};
        const Scene& scene = mDocument.scene();
        pairs = scene.pairs, warp = scene.warp, blend = scene.blend, timing = scene.timing;
        last = mMorpher;
        local = mLocalTime;
        lastVersion = mMorpherVersion;
        lastTiming = mMorpherTiming;
    }
    local = timingAt(local, timingVersion != lastTiming, timing, mTimingRegions);
    std::shared_ptr<const Morpher> morpher = last;
    if (!last) {
        MorphOptions options;
        options.influences = mInfluences;
        options.localTime = local;
        options.setupInterrupter = mInterrupter;
        morpher = std::make_shared<const Morpher>(mSource, mTarget, pairs, warp, blend, options);
    } else {
        if (lastVersion != version)
            morpher = std::make_shared<const Morpher>(morpher->withPairs(pairs));
        if (lastTiming != timingVersion)
            morpher = std::make_shared<const Morpher>(morpher->withTiming(local));
    }
    std::string surface = surfaceOf(morpher->frame(t, nullptr, mInterrupter), local.get());
    std::lock_guard<std::mutex> lock(mMutex);
    mMorpher = morpher;
    mLocalTime = local;
    mMorpherVersion = version;
    mMorpherTiming = timingVersion;
    keepMorphMesh(surface, version + timingVersion, t);
    return {200, "application/octet-stream", std::move(surface)};
}

Reply EditorSession::surfaceMesh(double t)
{
    std::lock_guard<std::mutex> one(mMorphMutex);
    SurfaceSpec spec;
    BlendSpec blend;
    TimingSettings timing;
    uint64_t version = 0, timingVersion = 0, lastTiming = 0;
    std::shared_ptr<const SurfaceMorpher> morpher;
    std::shared_ptr<const LocalTime> local;
    {
        std::lock_guard<std::mutex> lock(mMutex);
        version = mDocument.pairsVersion();
        timingVersion = mDocument.timingVersion();
        if (mMorphVersion == version + timingVersion && mMorphT == t)
            return {200, "application/octet-stream", mMorphMesh};
        spec = mDocument.scene().surface;
        blend = mDocument.scene().blend;
        timing = mDocument.scene().timing;
        if (mSurfaceVersion == version) morpher = mSurfaceMorpher;
        local = mLocalTime;
        lastTiming = mMorpherTiming;
    }
    local = timingAt(local, timingVersion != lastTiming, timing, mTimingRegions);
    if (!morpher) {
        try {
            morpher = std::make_shared<const SurfaceMorpher>(
                mSurfaceSides->first, mSurfaceSides->second, spec, mInterrupter);
        } catch (const UserError& e) { // a landmark off its surface, or one that folds the map
            throw Conflict(e.what());
        }
    }
    const SurfaceFrame frame = surfaceFrameAt(*morpher, blend, local.get(), t, 0.0);
    std::string mesh = encodeTriangles(frame.points, frame.triangles, local.get());
    std::lock_guard<std::mutex> lock(mMutex);
    mSurfaceMorpher = morpher;
    mSurfaceVersion = version;
    mLocalTime = local;
    mMorpherTiming = timingVersion;
    keepMorphMesh(mesh, version + timingVersion, t);
    return {200, "application/octet-stream", std::move(mesh)};
}

void EditorSession::keepMorphMesh(const std::string& mesh, uint64_t version, double t)
{
    mMorphMesh = mesh;
    mMorphVersion = version;
    mMorphT = t;
}

Reply EditorSession::route(const std::string& method, const std::string& route,
                           const std::string& body)
{
    if (route.rfind("/api/", 0) != 0) return error(404, "no such page");
    const std::string name = route.substr(5);
    if (method == "GET") {
        if (name == "state") return stateReply(mDocument);
        return error(404, "no such API call: GET " + route.substr(0, 80));
    }
    if (method != "POST") return error(405, "only GET and POST");
    const json request = parseBody(body);
    if (name == "save") {
        mDocument.save();
    } else if (name == "suggest") {
        if (mSurfaceSides)
            throw BadRequest("suggest: blend.mode = \"surface\" takes landmarks (point pairs), "
                             "placed by hand; pairs suggest proposes warp features");
        mDocument.appendPairs(suggestPairs(mSource, mTarget).pairs, kSuggestedPairComment);
    } else if (name == "set" || name == "add" || name == "duplicate" || name == "delete" ||
               name == "undo" || name == "redo") {
        mDocument.apply(name, request);
    } else {
        return error(404, "no such API call: POST " + route.substr(0, 80));
    }
    return stateReply(mDocument);
}

Reply EditorSession::handle(const std::string& method, const std::string& path,
                            const std::map<std::string, std::string>& query,
                            const std::string& body)
{
    try {
        if (method == "GET" && path == "/api/mesh") return sideMesh(query);
        std::lock_guard<std::mutex> lock(mMutex);
        return route(method, path, body);
    } catch (const Interrupted&) {
        return error(503, "the editor is stopping");
    } catch (const BadRequest& e) {
        return error(400, e.what());
    } catch (const Conflict& e) {
        return error(409, e.what());
    } catch (const UserError& e) {
        return error(500, e.what()); // the scene's own file could not be written
    } catch (const std::invalid_argument& e) {
        return error(400, e.what());
    } catch (const nlohmann::json::exception& e) {
        return error(400, std::string("malformed request: ") + e.what());
    } catch (const std::exception& e) {
        return error(500, e.what());
    }
}

} // namespace volmorph::editor
