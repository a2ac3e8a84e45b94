// The editor's API from C++ (tools/editor/EditorSession.h, EditDocument.h): load, edits and their
// undo, the validator's errors placed at the element they concern, save and re-read, malformed
// requests answered 400 with nothing changed, and the in-between's mesh after an edit (of the
// pairs, of the timing's sweep) equal byte for byte to the one a Morpher built anew with the edit
// gives.
#include "editor/EditorSession.h"

#include <volmorph/LocalTime.h>
#include <volmorph/SceneVolumes.h>
#include <volmorph/SurfaceMorph.h>

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>

using namespace volmorph;
using namespace volmorph::editor;
using nlohmann::json;

namespace {

const std::filesystem::path kRoot = VOLMORPH_SOURCE_DIR;

std::string readText(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

void writeText(const std::filesystem::path& path, const std::string& text)
{
    std::ofstream(path, std::ios::binary) << text;
}

/// A copy of scenes/NAME in a fresh folder, its mesh paths made absolute.
std::filesystem::path copyScene(const std::string& name)
{
    const std::filesystem::path folder =
        std::filesystem::temp_directory_path() /
        ("volmorph_edit_" + std::to_string(::getpid()) + "_" +
         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(folder);
    std::string text = readText(kRoot / "scenes" / name);
    for (const std::string from : {"\"meshes/", "\"skies/"}) {
        const std::string to = "\"" + (kRoot / "scenes").string() + "/" + from.substr(1);
        for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + 1))
            text.replace(at, from.size(), to);
    }
    writeText(folder / name, text);
    return folder / name;
}

int changedLines(const std::string& a, const std::string& b)
{
    std::istringstream ia(a), ib(b);
    int changed = 0;
    std::string la, lb;
    while (true) {
        const bool ga = bool(std::getline(ia, la)), gb = bool(std::getline(ib, lb));
        if (!ga && !gb) return changed;
        if (ga != gb) return -1;
        changed += la != lb;
    }
}

json post(EditorSession& s, const std::string& action, const std::string& body, int status = 200)
{
    const Reply r = s.handle("POST", "/api/" + action, {}, body);
    EXPECT_EQ(r.status, status) << action << " " << body << " -> " << r.body;
    return json::parse(r.body);
}

struct MeshHeader {
    uint32_t vertices = 0, triangles = 0;
    float lo[3], hi[3];
};

MeshHeader header(const std::string& mesh)
{
    MeshHeader h;
    EXPECT_EQ(mesh.substr(0, 4), "VMM1");
    std::memcpy(&h.vertices, mesh.data() + 4, 4);
    std::memcpy(&h.triangles, mesh.data() + 8, 4);
    std::memcpy(h.lo, mesh.data() + 12, 12);
    std::memcpy(h.hi, mesh.data() + 24, 12);
    const size_t indexStart = (36 + 6 * size_t(h.vertices) + 3) & ~size_t(3);
    EXPECT_EQ(mesh.size(), indexStart + 12 * size_t(h.triangles));
    return h;
}

} // namespace

TEST(EditApi, EditsUndoAndSaveKeepEveryOtherLine)
{
    const auto scene = copyScene("bunny-to-knot.toml");
    const std::string original = readText(scene);
    EditDocument doc(scene);
    ASSERT_EQ(doc.scene().pairs.size(), 3u);
    doc.apply("set",
              json::parse(R"({"key": "pair[2].target.origin", "value": [-0.4, 0.41, 0.02]})"));
    EXPECT_TRUE(doc.valid());
    EXPECT_EQ(doc.scene().pairs[1].target.origin, Vec3d(-0.4, 0.41, 0.02));
    EXPECT_EQ(changedLines(original, doc.text()), 1);
    EXPECT_TRUE(doc.state()["dirty"].get<bool>());
    const uint64_t version = doc.pairsVersion();
    doc.apply("set",
              json::parse(R"({"key": "pair[1].source.axes", "value": [[0, 1, 0], [-1, 0, 0]]})"));
    EXPECT_EQ(doc.pairsVersion(), version + 1);
    EXPECT_NEAR(doc.scene().pairs[0].source.zAxis.z(), 1.0, 1e-12);
    doc.apply("undo", json::object());
    doc.apply("redo", json::object());
    doc.apply("undo", json::object());
    EXPECT_EQ(changedLines(original, doc.text()), 1);
    doc.save();
    EXPECT_EQ(readText(scene), doc.text());
    EXPECT_FALSE(doc.state()["dirty"].get<bool>());
    // Re-read: the same pairs, the one value changed.
    const Scene reread = loadScene(scene);
    ASSERT_EQ(reread.pairs.size(), 3u);
    EXPECT_EQ(reread.pairs[1].target.origin, Vec3d(-0.4, 0.41, 0.02));
    EXPECT_EQ(reread.pairs[0].source.origin, doc.scene().pairs[0].source.origin);
    doc.apply("undo", json::object());
    EXPECT_EQ(doc.text(), original);
}

TEST(EditApi, AddDuplicateDeleteAndTheirUndo)
{
    const auto scene = copyScene("bunny-to-knot.toml");
    EditDocument doc(scene);
    const std::string original = doc.text();
    doc.apply("add", json::parse(R"({"type": "segment",
        "source": {"origin": [0, 0.5, 0], "axes": [[1, 0, 0], [0, 1, 0]], "scale": [0.3, 1, 1]},
        "target": {"origin": [0.1, 0.5, 0], "axes": [[0, 0, 1], [0, 1, 0]], "scale": 0.2}})"));
    ASSERT_TRUE(doc.valid()) << doc.errors().front().message;
    ASSERT_EQ(doc.scene().pairs.size(), 4u);
    EXPECT_EQ(doc.scene().pairs[3].type, FeatureType::Segment);
    EXPECT_EQ(doc.scene().pairs[3].target.scale, Vec3d(0.2));
    EXPECT_EQ(doc.scene().pairs[3].target.xAxis, Vec3d(0, 0, 1));
    doc.apply("add", json::parse(R"({"type": "point", "source": {"origin": [0, 0, 0]},
                                     "target": {"origin": [0, 1, 0]}})"));
    EXPECT_NE(doc.text().find("source = { origin = [0.0, 0.0, 0.0] }"), std::string::npos);
    doc.apply("duplicate", json::parse(R"({"index": 1})"));
    ASSERT_EQ(doc.scene().pairs.size(), 6u);
    EXPECT_EQ(doc.scene().pairs[5].target.scale, doc.scene().pairs[0].target.scale);
    doc.apply("delete", json::parse(R"({"index": 2})"));
    ASSERT_EQ(doc.scene().pairs.size(), 5u);
    EXPECT_EQ(doc.scene().pairs[1].source.origin, Vec3d(0.47, 0.25, 0.08)); // the old third
    for (int i = 0; i < 4; ++i) doc.apply("undo", json::object());
    EXPECT_EQ(doc.text(), original);
    EXPECT_THROW(doc.apply("undo", json::object()), BadRequest);
}

TEST(EditApi, ValidatorErrorsArePlacedAtTheirElement)
{
    const auto scene = copyScene("bunny-to-knot.toml");
    EditDocument doc(scene);
    const Vec3d kept = doc.scene().pairs[1].target.scale;
    doc.apply("set", json::parse(R"({"key": "pair[3].source.scale", "value": [0, 1, 1]})"));
    ASSERT_FALSE(doc.valid());
    ASSERT_EQ(doc.errors().size(), 1u);
    EXPECT_EQ(doc.errors()[0].pair, 3);
    EXPECT_EQ(doc.errors()[0].side, "source");
    EXPECT_NE(doc.errors()[0].message.find("scale"), std::string::npos);
    EXPECT_EQ(doc.scene().pairs.size(), 3u); // the last valid scene stays
    EXPECT_EQ(doc.scene().pairs[1].target.scale, kept);
    EXPECT_THROW(doc.save(), Conflict);
    EXPECT_THROW(doc.apply("duplicate", json::parse(R"({"index": 1})")), Conflict);
    doc.apply("set", json::parse(R"({"key": "pair[1].type", "value": "point"})"));
    doc.apply("set",
              json::parse(R"({"key": "pair[1].target.axes", "value": [[1, 0, 0], [2, 0, 0]]})"));
    bool parallel = false;
    for (const PlacedError& e : doc.errors())
        parallel |=
            e.pair == 1 && e.side == "target" && e.message.find("parallel") != std::string::npos;
    EXPECT_TRUE(parallel);
    doc.apply("undo", json::object());
    doc.apply("undo", json::object());
    doc.apply("undo", json::object());
    EXPECT_TRUE(doc.valid());
}

TEST(EditApi, MalformedRequestsAre400AndChangeNothing)
{
    const auto scene = copyScene("bunny-to-knot.toml");
    EditDocument doc(scene);
    const std::string original = doc.text();
    for (const char* body :
         {R"({"key": "pair[9].target.origin", "value": [0, 0, 0]})",
          R"({"key": "warp.epsilon", "value": 1})", R"({"key": "pair[1].target.origin"})",
          R"({"key": "pair[1].target.origin", "value": [0, 0]})",
          R"({"key": "pair[1].target.origin", "value": ["a", 0, 0]})",
          R"({"key": "pair[1].type", "value": "blob"})",
          R"({"key": "pair[1].type", "value": "box\" \n[evil]"})", R"([1, 2])", R"(3)",
          R"({"key": 7})"})
        EXPECT_THROW(doc.apply("set", json::parse(body)), BadRequest) << body;
    EXPECT_THROW(doc.apply("delete", json::parse(R"({"index": 0})")), BadRequest);
    EXPECT_THROW(doc.apply("delete", json::parse(R"({"index": "1"})")), BadRequest);
    EXPECT_THROW(doc.apply("add", json::parse(R"({"type": "box", "source": {}})")), BadRequest);
    EXPECT_THROW(doc.apply("rename", json::object()), BadRequest);
    EXPECT_EQ(doc.text(), original);
    EXPECT_FALSE(doc.state()["canUndo"].get<bool>());
}

TEST(EditApi, AHugeNumberIsWrittenSoTheFileStillReads)
{
    // The editor's fuzzer: an axis of 99e91 was written as a hundred-digit decimal, the file could
    // not be read back, and the refusal escaped as std::invalid_argument rather than a 400.
    const auto scene = copyScene("bunny-to-knot.toml");
    EditDocument doc(scene);
    doc.apply("add", json::parse(R"({"type": "box", "source": {"origin": [0, 0, 0],
        "axes": [[1, 0, 0], [99e91, 1, 0]], "scale": 5.5}, "target": {"origin": [0, 0, 0]}})"));
    EXPECT_NE(doc.text().find("[9.9e+92, 1.0, 0.0]"), std::string::npos);
    EXPECT_FALSE(doc.valid()); // the axes are not at right angles: a validator error, placed
    ASSERT_FALSE(doc.errors().empty());
    EXPECT_EQ(doc.errors().front().pair, 4);
    doc.apply("undo", json::object());
    EXPECT_TRUE(doc.valid());
}

TEST(EditApi, SaveRefusesAFileChangedOnDisk)
{
    const auto scene = copyScene("bunny-to-knot.toml");
    EditDocument doc(scene);
    doc.apply("set", json::parse(R"({"key": "pair[2].source.origin", "value": [0, 0, 0]})"));
    writeText(scene, readText(scene) + "\n# edited by hand meanwhile\n");
    EXPECT_THROW(doc.save(), Conflict);
    EXPECT_NE(readText(scene).find("edited by hand meanwhile"), std::string::npos);
}

TEST(EditApi, SessionAnswersAndTheInBetweenFollowsTheEdits)
{
    const auto scene = copyScene("sphere-to-box.toml");
    EditorSession session(scene, 32, nullptr);
    const json state = json::parse(session.handle("GET", "/api/state", {}, "").body);
    ASSERT_EQ(state["pairs"].size(), 1u);
    EXPECT_EQ(state["pairs"][0]["type"], "box");
    // The sides' surfaces: the sphere (radius 0.5) at the origin, the cube of side 0.8 at x = 1.5.
    const MeshHeader source =
        header(session.handle("GET", "/api/mesh", {{"of", "source"}}, "").body);
    EXPECT_NEAR(0.5 * (source.lo[0] + source.hi[0]), 0.0, 0.05);
    const MeshHeader target =
        header(session.handle("GET", "/api/mesh", {{"of", "target"}}, "").body);
    EXPECT_NEAR(0.5 * (target.lo[0] + target.hi[0]), 1.5, 0.05);
    // The box pair is an affine map: the in-between at t = 0.5 is centred half way.
    const Reply morph = session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "0.5"}}, "");
    ASSERT_EQ(morph.status, 200);
    const MeshHeader half = header(morph.body);
    EXPECT_GT(half.triangles, 100u);
    EXPECT_NEAR(0.5 * (half.lo[0] + half.hi[0]), 0.75, 0.05);

    post(session, "set", R"({"key": "pair[1].target.origin", "value": [1.2, 0.1, 0]})");
    const std::string edited =
        session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "0.5"}}, "").body;
    // A Morpher made anew with the edited scene gives the same surface, byte for byte.
    Scene fresh = loadScene(scene);
    EXPECT_EQ(changedLines(readText(scene), session.document().text()), 1);
    fresh = parseScene(session.document().text(), scene);
    fresh.volume.voxelSize.reset();
    fresh.volume.resolution = 32;
    const SceneVolumes volumes = voxelizeScene(fresh);
    const Morpher morpher(volumes.source, volumes.target, fresh.pairs, fresh.warp, fresh.blend);
    EXPECT_EQ(edited, surfaceOf(morpher.frame(0.5)));

    EXPECT_EQ(session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "2"}}, "").status, 400);
    EXPECT_EQ(session.handle("GET", "/api/mesh", {{"of", "/etc/passwd"}}, "").status, 400);
    EXPECT_EQ(session.handle("GET", "/api/nothing", {}, "").status, 404);
    EXPECT_EQ(session.handle("POST", "/api/set", {}, "{bad").status, 400);
    EXPECT_EQ(session.handle("POST", "/api/set", {}, std::string(100, '[')).status, 400);
    const json saved = post(session, "save", "{}");
    EXPECT_FALSE(saved["dirty"].get<bool>());
    EXPECT_EQ(loadScene(scene).pairs[0].target.origin, Vec3d(1.2, 0.1, 0));
    // Suggest appends after the scene's own pairs, as one step of undo.
    const json suggested = post(session, "suggest", "{}");
    EXPECT_GE(suggested["pairs"].size(), 2u);
    EXPECT_EQ(post(session, "undo", "{}")["pairs"].size(), 1u);
}

TEST(EditApi, TheSweepIsDraggedAndTheInBetweenCarriesItsDelays)
{
    const auto scene = copyScene("bunny-to-knot-sweep.toml");
    const std::string original = readText(scene);
    EditorSession session(scene, 32, nullptr);
    const json state = json::parse(session.handle("GET", "/api/state", {}, "").body);
    EXPECT_EQ(state["timing"]["spread"], 0.5);
    EXPECT_EQ(state["timing"]["sweep"]["direction"], json::parse("[0, 1, 0]"));
    // Direction and length in one step, as the page sends a dragged end handle.
    const json turned = post(session, "set",
                             R"({"values": {"timing.sweep.direction": [0.6, 0.8, 0],
                                            "timing.sweep.length": 0.8}})");
    EXPECT_EQ(turned["timing"]["sweep"]["direction"], json::parse("[0.6, 0.8, 0]"));
    EXPECT_EQ(turned["timing"]["sweep"]["length"], 0.8);
    EXPECT_EQ(changedLines(original, session.document().text()), 1);
    // The in-between under the turned sweep, each vertex with its delay ("VMM2"): byte for byte
    // what a Morpher built anew with the edited scene gives, its delays from the same timing.
    const std::string mesh =
        session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "0.5"}}, "").body;
    ASSERT_EQ(mesh.substr(0, 4), "VMM2");
    Scene fresh = parseScene(session.document().text(), scene);
    fresh.volume.voxelSize.reset();
    fresh.volume.resolution = 32;
    SceneVolumes volumes = voxelizeScene(fresh);
    MorphOptions options;
    options.localTime = std::make_shared<const LocalTime>(fresh.timing, volumes.timingRegions);
    const Morpher morpher(volumes.source, volumes.target, fresh.pairs, fresh.warp, fresh.blend,
                          options);
    EXPECT_EQ(mesh, surfaceOf(morpher.frame(0.5), options.localTime.get()));
    uint32_t vertices = 0, triangles = 0;
    std::memcpy(&vertices, mesh.data() + 4, 4);
    std::memcpy(&triangles, mesh.data() + 8, 4);
    const size_t delaysAt = ((36 + 6 * size_t(vertices) + 3) & ~size_t(3)) + 12 * size_t(triangles);
    ASSERT_EQ(mesh.size(), delaysAt + 4 * size_t(vertices));
    float lo = 1.0f, hi = 0.0f;
    for (uint32_t i = 0; i < vertices; ++i) {
        float d;
        std::memcpy(&d, mesh.data() + delaysAt + 4 * i, 4);
        lo = std::min(lo, d), hi = std::max(hi, d);
    }
    EXPECT_GE(lo, 0.0f);
    EXPECT_LE(hi, 0.5f);
    EXPECT_GT(hi - lo, 0.25f); // the sweep crosses the shapes
    // One step of undo; keys the page may not set, or a sweep the file lacks: 400.
    post(session, "undo", "{}");
    EXPECT_EQ(session.document().text(), original);
    post(session, "set", R"({"key": "timing.region", "value": 1})", 400);
    post(session, "set", R"({"values": {"timing.sweep.origin": [0, 0]}})", 400);
    EXPECT_EQ(session.document().text(), original);
    const auto plain = copyScene("sphere-to-box.toml");
    EditorSession none(plain, 32, nullptr);
    post(none, "set", R"({"key": "timing.sweep.origin", "value": [0, 0, 0]})", 400);
    EXPECT_EQ(json::parse(none.handle("GET", "/api/state", {}, "").body)["timing"]["sweep"],
              nullptr);
}

TEST(EditApi, SurfaceModeShowsTheMeshesAndItsLandmarksMoveTheInBetween)
{
    const auto scene = copyScene("blobby-to-star-surface.toml");
    EditorSession session(scene, 32, nullptr);
    const json state = json::parse(session.handle("GET", "/api/state", {}, "").body);
    EXPECT_TRUE(state["landmarks"].get<bool>());
    ASSERT_EQ(state["pairs"].size(), 3u);
    // The sides are the mesh files as placed, not voxelized: their bounds exactly.
    const SceneMeshes meshes = importSceneMeshes(loadScene(scene));
    const MeshHeader source =
        header(session.handle("GET", "/api/mesh", {{"of", "source"}}, "").body);
    EXPECT_EQ(source.vertices, meshes.source.points.size());
    EXPECT_EQ(source.triangles, meshes.source.triangles.size());
    const auto [lo, hi] = meshes.source.bounds();
    for (int i = 0; i < 3; ++i) EXPECT_FLOAT_EQ(source.lo[i], float(lo[i]));
    for (int i = 0; i < 3; ++i) EXPECT_FLOAT_EQ(source.hi[i], float(hi[i]));

    // Each in-between is the surface stage's, byte for byte, before and after a landmark's move.
    const auto fresh = [&](double t) {
        const Scene s = parseScene(session.document().text(), scene);
        const SurfaceMorpher morpher(meshes.source, meshes.target, s.surface);
        const SurfaceFrame f = morpher.frame(t, t); // linear schedules: tau = t
        return encodeTriangles(f.points, f.triangles);
    };
    const std::string before =
        session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "0.5"}}, "").body;
    EXPECT_EQ(before, fresh(0.5));
    post(session, "set", R"({"key": "pair[3].target.origin", "value": [0, 0.5, 0.5]})");
    const std::string after =
        session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "0.5"}}, "").body;
    EXPECT_NE(after, before);
    EXPECT_EQ(after, fresh(0.5));

    // A landmark far off its surface: the correspondence refuses it, 409 naming the pair's line.
    post(session, "set", R"({"key": "pair[3].target.origin", "value": [5, 5, 5]})");
    const Reply off = session.handle("GET", "/api/mesh", {{"of", "morph"}, {"t", "0.25"}}, "");
    EXPECT_EQ(off.status, 409);
    EXPECT_NE(off.body.find("blobby-to-star-surface.toml:"), std::string::npos) << off.body;
    // No suggestions, and a segment is an error placed at its pair.
    EXPECT_EQ(session.handle("POST", "/api/suggest", {}, "{}").status, 400);
    const json segment = post(session, "set", R"({"key": "pair[1].type", "value": "segment"})");
    EXPECT_FALSE(segment["valid"].get<bool>());
    EXPECT_EQ(segment["errors"][0]["pair"], 1);
}
