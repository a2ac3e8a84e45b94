#include <volmorph/Scene.h>
#include "KeyframeTrack.h" // tools/: the CLI's keyframe track (header-only)

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace volmorph;

namespace {

const std::filesystem::path kRoot = VOLMORPH_SOURCE_DIR;
// Inline scenes are "located" in tests/data so that mesh paths like meshes/cube.obj resolve.
const std::filesystem::path kInline = kRoot / "tests" / "data" / "inline.toml";

const char* kMinimal = R"(
[source]
mesh = "meshes/cube.obj"
[target]
mesh = "meshes/tetra.off"
[volume]
voxel_size = 0.05
)";

Scene parse(const std::string& text)
{
    return parseScene(text, kInline);
}

/// Parses `text` expecting failure; returns the diagnostics.
std::vector<Diagnostic> errors(const std::string& text)
{
    try {
        parse(text);
    } catch (const UserError& e) {
        return e.diagnostics();
    }
    ADD_FAILURE() << "expected a UserError for:\n" << text;
    return {};
}

/// Expects exactly one error, at line:col, whose message contains `fragment`.
void expectError(const std::string& text, int line, int column, const std::string& fragment)
{
    const std::vector<Diagnostic> d = errors(text);
    ASSERT_EQ(d.size(), 1u) << (d.empty() ? "" : d[0].str());
    EXPECT_EQ(d[0].where.file, kInline.string());
    EXPECT_EQ(d[0].where.line, line) << d[0].str();
    EXPECT_EQ(d[0].where.column, column) << d[0].str();
    EXPECT_NE(d[0].message.find(fragment), std::string::npos) << d[0].str();
}

/// expectError on the minimal scene followed by `added` (whose first line is the scene's line 9).
void expectAddedError(const std::string& added, int line, int column, const std::string& fragment)
{
    expectError(std::string(kMinimal) + added, line, column, fragment);
}

std::string withPair(const std::string& pair)
{
    return std::string(kMinimal) + "[[pair]]\n" + pair;
}

} // namespace

TEST(Scene, EveryExampleSceneLoads)
{
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(kRoot / "scenes")) {
        if (entry.path().extension() != ".toml") continue;
        ++count;
        EXPECT_NO_THROW({
            const Scene s = loadScene(entry.path());
            EXPECT_TRUE(std::filesystem::exists(s.source.file()));
            EXPECT_TRUE(std::filesystem::exists(s.target.file()));
            // Every example places pairs, but a timing's (which takes none yet).
            EXPECT_TRUE(!s.pairs.empty() || s.timing.spread > 0.0);
        }) << entry.path();
    }
    EXPECT_GE(count, 3);
}

TEST(Scene, DefaultSceneValues)
{
    const Scene s = loadScene(kRoot / "scenes" / "bunny-to-knot.toml");
    EXPECT_EQ(s.source.mesh, kRoot / "scenes" / "meshes" / "bunny.obj");
    EXPECT_DOUBLE_EQ(*s.volume.voxelSize, 0.008);
    ASSERT_EQ(s.pairs.size(), 3u);
    EXPECT_EQ(s.pairs[0].type, FeatureType::Box);
    EXPECT_EQ(s.pairs[1].type, FeatureType::Point);
    EXPECT_EQ(s.blend.mode, BlendMode::Sdf);
    EXPECT_EQ(s.blend.minIslandVoxels, 100);
    EXPECT_EQ(s.blend.density.kind, ScheduleSpec::Kind::Sigmoid);
    EXPECT_DOUBLE_EQ(s.blend.density.k, 8.0);
    EXPECT_EQ(s.render.lights.size(), 2u);
    EXPECT_NEAR(s.render.lights[0].angleRadians, 2.0 * M_PI / 180.0, 1e-12);
    EXPECT_EQ(s.render.lights[1].type, LightType::Environment);
    EXPECT_EQ(s.render.lights[1].map, kRoot / "scenes" / "skies" / "sky.exr");
    EXPECT_EQ(s.render.bounces, 4);
    ASSERT_EQ(s.props.size(), 1u);
    EXPECT_EQ(s.props[0].mesh, kRoot / "scenes" / "meshes" / "floor.obj");
    EXPECT_EQ(s.frames.first, 1);
    EXPECT_EQ(s.frames.last, 24);
}

TEST(Scene, FeatureAxesAreNormalizedOnReading)
{
    const Scene s = parseScene(R"(
[source]
mesh = "meshes/bunny.obj"
[target]
mesh = "meshes/knot1.off"
[volume]
voxel_size = 0.01
[[pair]]
type = "segment"
source = { origin = [0, 0.9, 0], axes = [[0.707, 0, 0.707], [0, 1, 0]], scale = [0.5, 0.1, 0.1] }
target = { origin = [0, 0.9, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [0.5, 0.1, 0.1] }
)",
                               kRoot / "scenes" / "inline.toml");
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_NEAR(s.pairs[0].source.xAxis.length(), 1.0, 1e-12);
    EXPECT_NEAR(s.pairs[0].source.xAxis.x(), std::sqrt(0.5), 1e-12);
    EXPECT_EQ(s.blend.minIslandVoxels, 27);
}

TEST(Scene, MinimalSceneGetsDocumentedDefaults)
{
    const Scene s = parse(kMinimal);
    EXPECT_TRUE(s.source.transform.isIdentity());
    EXPECT_FALSE(s.source.color.has_value());
    EXPECT_TRUE(s.pairs.empty());
    EXPECT_DOUBLE_EQ(s.warp.epsilon, 0.01);
    EXPECT_DOUBLE_EQ(s.warp.toleranceVoxels, 0.25);
    EXPECT_EQ(s.blend.mode, BlendMode::Density);
    EXPECT_EQ(s.render.width, 960);
    EXPECT_EQ(s.render.height, 540);
    EXPECT_EQ(s.render.samples, 4);
    EXPECT_DOUBLE_EQ(s.render.stepVoxels, 0.5);
    EXPECT_EQ(s.render.lights.size(), 1u); // the default key light
    EXPECT_NEAR(s.render.lights[0].direction.length(), 1.0, 1e-12);
    EXPECT_EQ(s.frames.first, 1);
    EXPECT_EQ(s.frames.last, 1);
}

TEST(Scene, PointFeaturesMayOmitAxesAndScale)
{
    const Scene s = parse(withPair("type = \"point\"\nsource = { origin = [1, 2, 3] }\n"
                                   "target = { origin = [4, 5, 6] }\n"));
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_EQ(s.pairs[0].source.origin, Vec3d(1, 2, 3));
    EXPECT_EQ(s.pairs[0].source.xAxis, Vec3d(1, 0, 0));
    EXPECT_EQ(s.pairs[0].source.scale, Vec3d(1, 1, 1));
    EXPECT_EQ(s.pairs[0].target.origin, Vec3d(4, 5, 6));
    EXPECT_EQ(s.pairs[0].where.line, 8);
}

TEST(Scene, SlightlySkewedAxesAreMadeOrthonormal)
{
    const Scene s = parse(withPair(
        "type = \"box\"\n"
        "source = { origin = [0, 0, 0], axes = [[2, 0, 0], [0.05, 1, 0]], scale = [1, 2, 3] }\n"
        "target = { origin = [0, 0, 0], axes = [[0, 0, 1], [0, 1, 0]], scale = [1, 2, 3] }\n"));
    const FeatureElement& e = s.pairs[0].source;
    EXPECT_NEAR(e.xAxis.dot(e.yAxis), 0.0, 1e-12);
    EXPECT_NEAR(e.yAxis.length(), 1.0, 1e-12);
    EXPECT_EQ(e.xAxis, Vec3d(1, 0, 0)); // x is kept, y adjusted
    EXPECT_NEAR((e.zAxis - Vec3d(0, 0, 1)).length(), 0.0, 1e-12);
    // z = x cross y: [0,0,1] x [0,1,0] = [-1,0,0].
    EXPECT_NEAR((s.pairs[0].target.zAxis - Vec3d(-1, 0, 0)).length(), 0.0, 1e-12);
}

TEST(SceneTransform, ScaleThenRotateXYZThenTranslate)
{
    ObjectTransform xf;
    xf.rotateRadians = Vec3d(0, M_PI / 2, 0);
    // A right-handed rotation of +90 degrees about y takes +x to -z.
    EXPECT_NEAR((xf.apply(Vec3d(1, 0, 0)) - Vec3d(0, 0, -1)).length(), 0.0, 1e-12);
    xf.scale = Vec3d(2.0);
    xf.translate = Vec3d(10, 0, 0);
    EXPECT_NEAR((xf.apply(Vec3d(1, 0, 0)) - Vec3d(10, 0, -2)).length(), 0.0, 1e-12);
    // X first, then Y: +y -> (rotate X 90) +z -> (rotate Y 90) +x.
    ObjectTransform xy;
    xy.rotateRadians = Vec3d(M_PI / 2, M_PI / 2, 0);
    EXPECT_NEAR((xy.apply(Vec3d(0, 1, 0)) - Vec3d(1, 0, 0)).length(), 0.0, 1e-12);
}

TEST(Scene, TransformReadsDegrees)
{
    const Scene s = parse(R"(
[source]
mesh = "meshes/cube.obj"
transform = { translate = [1, 2, 3], rotate = [0, 90, 0], scale = [1, 2, 3] }
[target]
mesh = "meshes/cube.obj"
transform = { scale = 0.5 }
[volume]
resolution = 64
)");
    EXPECT_NEAR(s.source.transform.rotateRadians.y(), M_PI / 2, 1e-12);
    EXPECT_EQ(s.source.transform.scale, Vec3d(1, 2, 3));
    EXPECT_EQ(s.target.transform.scale, Vec3d(0.5));
    EXPECT_EQ(*s.volume.resolution, 64);
    EXPECT_FALSE(s.volume.voxelSize.has_value());
}

TEST(SceneErrors, SyntaxError)
{
    expectError("[source\nmesh = 1\n", 1, 8, "TOML syntax error");
}

TEST(SceneErrors, UnknownKeySuggestsNearMiss)
{
    expectAddedError("[warp]\nepsilom = 0.1\n", 9, 1, "did you mean 'epsilon'?");
}

TEST(SceneErrors, UnknownKeyListsChoicesWhenNothingIsClose)
{
    expectAddedError("[frames]\nzzz = 1\n", 9, 1, "expected one of: range, output, fps");
}

TEST(SceneErrors, WrongType)
{
    expectAddedError("[render]\nresolution = \"640x480\"\n", 9, 14,
                     "render.resolution: expected [width, height] in pixels");
    expectAddedError("[warp]\nepsilon = \"small\"\n", 9, 11,
                     "warp.epsilon: expected a number, got a string");
    expectAddedError("[render]\ncamera = 3\n", 9, 10,
                     "render.camera: expected a table, got an integer");
}

TEST(SceneErrors, OutOfRange)
{
    const std::string base =
        "[source]\nmesh = \"meshes/cube.obj\"\n[target]\nmesh = \"meshes/cube.obj\"\n";
    expectError(base + "[volume]\nvoxel_size = -0.5\n", 6, 14, "positive length in world units");
    expectError(base + "[volume]\nvoxel_size = 0.0\n", 6, 14, "positive length in world units");
    expectError(base + "[volume]\nresolution = 2\n", 6, 14, "from 8 to 16384");
    expectAddedError("[render]\nsamples = 0\n", 9, 11, "from 1 to 65536");
    expectAddedError("[render]\ncamera = { fov = 180 }\n", 9, 18, "0 < fov <= 179");
    expectAddedError("[render]\nanisotropy = -1\n", 9, 14, "-1 < g < 1");
}

TEST(SceneErrors, NanAndInf)
{
    expectAddedError("[warp]\nepsilon = nan\n", 9, 11, "expected a finite number, got nan");
    expectAddedError("[render]\ncamera = { eye = [0, -inf, 5] }\n", 9, 22,
                     "render.camera.eye[1]: expected a finite number, got -inf");
}

TEST(SceneErrors, ZeroScale)
{
    expectError(
        withPair(
            "type = \"segment\"\n"
            "source = { origin = [0, 0, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [0, 1, 1] }\n"
            "target = { origin = [0, 0, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [1, 1, 1] }\n"),
        10, 71, "pair[1].source.scale: expected every component > 0");
}

TEST(SceneErrors, ZeroLengthParallelAndSkewedAxes)
{
    const std::string tail =
        "target = { origin = [0, 0, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [1, 1, 1] }\n";
    expectError(
        withPair("type = \"box\"\nsource = { origin = [0, 0, 0], axes = [[0, 0, 0], [0, 1, 0]], "
                 "scale = [1, 1, 1] }\n" +
                 tail),
        10, 40, "an axis has zero length");
    expectError(
        withPair("type = \"box\"\nsource = { origin = [0, 0, 0], axes = [[0, 1, 0], [0, 3, 0]], "
                 "scale = [1, 1, 1] }\n" +
                 tail),
        10, 39, "parallel");
    expectError(
        withPair("type = \"box\"\nsource = { origin = [0, 0, 0], axes = [[1, 0, 0], [1, 1, 0]], "
                 "scale = [1, 1, 1] }\n" +
                 tail),
        10, 39, "they are 45 degrees apart");
}

TEST(SceneErrors, NonPointFeatureNeedsAxesAndScale)
{
    const std::vector<Diagnostic> d = errors(withPair(
        "type = \"rectangle\"\nsource = { origin = [0, 0, 0] }\n"
        "target = { origin = [0, 0, 0], axes = [[1, 0, 0], [0, 1, 0]], scale = [1, 1, 1] }\n"));
    ASSERT_EQ(d.size(), 2u);
    EXPECT_NE(d[0].message.find("missing pair[1].source.axes"), std::string::npos) << d[0].str();
    EXPECT_NE(d[1].message.find("missing pair[1].source.scale"), std::string::npos) << d[1].str();
    EXPECT_EQ(d[0].where.line, 10);
}

TEST(SceneErrors, UnknownFeatureTypeSuggests)
{
    expectError(withPair("type = \"sgement\"\nsource = { origin = [0, 0, 0] }\ntarget = { origin = "
                         "[0, 0, 0] }\n"),
                9, 8, "did you mean \"segment\"?");
}

TEST(SceneErrors, MissingMeshFile)
{
    expectError("[source]\nmesh = \"meshes/nope.obj\"\n[target]\nmesh = \"meshes/cube.obj\"\n"
                "[volume]\nvoxel_size = 1\n",
                2, 8, "source.mesh: file not found: 'meshes/nope.obj'");
}

TEST(SceneErrors, MissingRequiredTables)
{
    const std::vector<Diagnostic> d = errors("[volume]\nvoxel_size = 1\n");
    ASSERT_EQ(d.size(), 2u);
    EXPECT_NE(d[0].message.find("missing [source]"), std::string::npos);
    EXPECT_NE(d[1].message.find("missing [target]"), std::string::npos);
}

TEST(SceneErrors, VoxelSizeAndResolutionExcludeEachOther)
{
    expectError("[source]\nmesh = \"meshes/cube.obj\"\n[target]\nmesh = \"meshes/cube.obj\"\n"
                "[volume]\nvoxel_size = 1\nresolution = 64\n",
                7, 14, "either voxel_size or resolution");
}

TEST(SceneErrors, FrameRanges)
{
    for (const char* bad : {"\"1-\"", "\"x\"", "\"10-1\"", "\"\"", "\"1-2-3\"", "\"1 - 5\""})
        expectAddedError(std::string("[frames]\nrange = ") + bad + "\noutput = \"o.#.exr\"\n", 9, 9,
                         "frames.range: expected \"FIRST-LAST\"");
}

TEST(SceneErrors, OutputPattern)
{
    expectAddedError("[frames]\nrange = \"1-3\"\noutput = \"frame.exr\"\n", 10, 10,
                     "no frame number placeholder");
    expectAddedError("[frames]\noutput = \"frame.png\"\n", 9, 10, "ending in .exr");
}

TEST(SceneErrors, Schedules)
{
    struct Bad {
        const char* value; // of blend.density or blend.color, on the scene's line 9
        int column;
        const char* fragment;
    };
    for (const Bad& bad :
         {Bad{"density = \"sigmoid(-2)\"", 11, "0 < k <= 1000"},
          Bad{"density = \"easein\"", 11, "unknown schedule"},
          Bad{"color = [[0, 0], [0.5, 0.7], [0.6, 0.4], [1, 1]]", 30, "tau must not decrease"},
          Bad{"color = [[0, 0], [0.5, 0.7]]", 9, "ending at [1, 1]"}}) {
        SCOPED_TRACE(bad.value);
        expectAddedError(std::string("[blend]\n") + bad.value + "\n", 9, bad.column, bad.fragment);
    }
}

TEST(SceneErrors, CameraAndLights)
{
    expectAddedError("[render]\ncamera = { eye = [1, 1, 1], lookat = [1, 1, 1] }\n", 9, 10,
                     "eye and lookat are the same point");
    expectAddedError("[render]\ncamera = { eye = [0, 5, 0], lookat = [0, 0, 0] }\n", 9, 10,
                     "up is parallel to the view direction");
    expectAddedError("[render]\nlights = [ { type = \"directional\", direction = [0, 0, 0] } ]\n",
                     9, 48, "render.lights[1].direction: expected a non-zero direction");
    const std::vector<Diagnostic> d =
        errors(std::string(kMinimal) +
               "[render]\nlights = [ { type = \"point\", direction = [0, 0, 1] } ]\n");
    ASSERT_EQ(d.size(), 2u);
    EXPECT_EQ(d[0].where.str(), kInline.string() + ":9:12");
    EXPECT_NE(d[0].message.find("missing render.lights[1].position"), std::string::npos);
    EXPECT_EQ(d[1].where.str(), kInline.string() + ":9:42");
    EXPECT_NE(d[1].message.find("a point light has a position, not a direction"),
              std::string::npos);
}

TEST(SceneErrors, BeierNeelyParametersNeedThatWeighting)
{
    expectAddedError("[warp]\nb = 2\n", 9, 5, "only used with weighting = \"beier-neely\"");
    EXPECT_NO_THROW(parse(std::string(kMinimal) +
                          "[warp]\nweighting = \"beier-neely\"\na = 0.1\nb = 2\np = 0.5\n"));
}

TEST(SceneErrors, EveryErrorInAFileIsReported)
{
    const std::vector<Diagnostic> d = errors(R"([source]
mesh = "meshes/cube.obj"
colour = [1, 0, 0]
[target]
mesh = "meshes/cube.obj"
[volume]
voxel_size = 0
[render]
samples = 2.5
[frames]
range = "a-b"
)");
    ASSERT_EQ(d.size(), 4u);
    EXPECT_EQ(d[0].where.line, 3);
    EXPECT_NE(d[0].message.find("did you mean 'color'"), std::string::npos);
    EXPECT_EQ(d[1].where.line, 7);
    EXPECT_EQ(d[2].where.line, 9);
    EXPECT_EQ(d[3].where.line, 11);
}

TEST(FrameRange, Parses)
{
    int a = 0, b = 0;
    EXPECT_TRUE(parseFrameRange("1-48", a, b));
    EXPECT_EQ(a, 1);
    EXPECT_EQ(b, 48);
    EXPECT_TRUE(parseFrameRange("7", a, b));
    EXPECT_EQ(a, 7);
    EXPECT_EQ(b, 7);
    EXPECT_TRUE(parseFrameRange("-5--1", a, b));
    EXPECT_EQ(a, -5);
    EXPECT_EQ(b, -1);
    EXPECT_TRUE(parseFrameRange("-3-2", a, b));
    EXPECT_EQ(a, -3);
    EXPECT_EQ(b, 2);
    EXPECT_FALSE(parseFrameRange("", a, b));
    EXPECT_FALSE(parseFrameRange("-", a, b));
    EXPECT_FALSE(parseFrameRange("2-1", a, b));
    EXPECT_FALSE(parseFrameRange("12345678901-2", a, b));
}

TEST(FrameRange, TimeOfFrame)
{
    FramesSpec f;
    f.first = 1;
    f.last = 5;
    EXPECT_DOUBLE_EQ(f.t(1), 0.0);
    EXPECT_DOUBLE_EQ(f.t(3), 0.5);
    EXPECT_DOUBLE_EQ(f.t(5), 1.0);
    f.last = 1;
    EXPECT_DOUBLE_EQ(f.t(1), 0.0);
}

TEST(Scene, CommentedExampleInScenesReadmeParses)
{
    // scenes/README.md's "fully commented example" is documentation users copy; it must stay valid.
    std::ifstream in(kRoot / "scenes" / "README.md");
    std::string line, toml;
    bool inExample = false, seenHeading = false;
    while (std::getline(in, line)) {
        if (line.rfind("## A fully commented example", 0) == 0)
            seenHeading = true;
        else if (seenHeading && !inExample && line == "```toml")
            inExample = true;
        else if (inExample && line == "```")
            break;
        else if (inExample)
            toml += line + "\n";
    }
    ASSERT_FALSE(toml.empty());
    const Scene s = parseScene(toml, kRoot / "scenes" / "README-example.toml");
    EXPECT_EQ(s.pairs.size(), 2u);
    EXPECT_NEAR(s.source.transform.rotateRadians.y(), M_PI / 2, 1e-12);
    ASSERT_EQ(s.render.lights.size(), 2u);
    EXPECT_EQ(s.render.lights[1].map, kRoot / "scenes" / "skies" / "sky.exr");
    EXPECT_EQ(s.render.bounces, 4);
    EXPECT_TRUE(s.render.layers);
    ASSERT_EQ(s.props.size(), 1u);
    EXPECT_EQ(s.props[0].color, Vec3d(0.6));
    EXPECT_EQ(s.frames.count(), 24);
}

TEST(SceneAnimation, CameraKeysInterpolateLinearlyAndHoldOutside)
{
    const Scene s = parse(std::string(kMinimal) + R"(
[render]
emission = [0.5, 0.25, 0]
camera = { eye = [0, 0, 5], lookat = [0, 0, 0], fov = 40, keys = [
    { frame = 10, eye = [0, 0, 5] },
    { frame = 20, eye = [10, 0, 5], fov = 60, lookat = [2, 0, 0] } ] }
)");
    EXPECT_EQ(s.render.emission, Vec3d(0.5, 0.25, 0.0));
    ASSERT_EQ(s.render.camera.keys.size(), 2u);
    // Values a key leaves out come from the camera.
    EXPECT_DOUBLE_EQ(s.render.camera.keys[0].fovDegrees, 40.0);
    const CameraSpec before = cli::cameraAt(s.render.camera, 1),
                     middle = cli::cameraAt(s.render.camera, 15),
                     after = cli::cameraAt(s.render.camera, 99);
    EXPECT_EQ(before.eye, Vec3d(0, 0, 5));
    EXPECT_EQ(after.eye, Vec3d(10, 0, 5));
    EXPECT_DOUBLE_EQ(after.fovDegrees, 60.0);
    EXPECT_NEAR(middle.eye.x(), 5.0, 1e-12);
    EXPECT_NEAR(middle.lookat.x(), 1.0, 1e-12);
    EXPECT_NEAR(middle.fovDegrees, 50.0, 1e-12);
    EXPECT_NEAR(middle.up.length(), 1.0, 1e-12);
    EXPECT_TRUE(middle.keys.empty());
}

TEST(SceneAnimation, LightKeysTurnTheDirectionAndFadeTheIntensity)
{
    const Scene s = parse(std::string(kMinimal) + R"(
[render]
lights = [ { type = "directional", direction = [0, -1, 0], intensity = 2, keys = [
    { frame = 1 },
    { frame = 3, direction = [1, 0, 0], intensity = 0, color = [1, 0, 0] } ] } ]
)");
    ASSERT_EQ(s.render.lights.size(), 1u);
    const LightSpec middle = cli::lightAt(s.render.lights[0], 2);
    EXPECT_NEAR(middle.direction.x(), std::sqrt(0.5),
                1e-12); // halfway between -y and +x, unit length
    EXPECT_NEAR(middle.direction.y(), -std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(middle.intensity, 1.0, 1e-12);
    EXPECT_NEAR(middle.color.y(), 0.5, 1e-12);
    EXPECT_EQ(cli::lightAt(s.render.lights[0], 0).intensity, 2.0);
}

TEST(SceneAnimation, KeyErrorsNameTheirPlace)
{
    const std::string base = std::string(kMinimal) + "[render]\n";
    expectError(base + "camera = { keys = [ { frame = 5 }, { frame = 5 } ] }\n", 9, 46,
                "render.camera.keys[2].frame: frames must increase from key to key (the key before "
                "is frame 5)");
    expectError(base + "camera = { keys = [ { eye = [1, 2, 3] } ] }\n", 9, 21,
                "missing render.camera.keys[1].frame");
    expectError(base + "camera = { keys = [ { frame = 1, lookat = [0, 0, 5] } ] }\n", 9, 21,
                "render.camera.keys[1]: eye and lookat are the same point");
    expectError(
        base + "lights = [ { type = \"point\", position = [0, 1, 0], keys = [ { frame = 1, "
               "direction = [0, 1, 0] } ] } ]\n",
        9, 86, "render.lights[1].keys[1].direction: a point light has a position, not a direction");
    expectError(base + "emission = [1, -1, 0]\n", 9, 12, "render.emission");
}

TEST(Scene, BouncesAndAnEnvironmentLight)
{
    const Scene scene = parse(std::string(kMinimal) +
                              "[render]\nbounces = 16\nlights = [ { type = \"environment\", "
                              "color = [0.5, 0.6, 1], intensity = 2 } ]\n");
    EXPECT_EQ(scene.render.bounces, 16);
    ASSERT_EQ(scene.render.lights.size(), 1u);
    EXPECT_EQ(scene.render.lights[0].type, LightType::Environment);
    EXPECT_EQ(scene.render.lights[0].intensity, 2.0);
    EXPECT_EQ(parse(kMinimal).render.bounces, 0); // the documented default
    const std::string base = std::string(kMinimal) + "[render]\n";
    expectError(base + "bounces = -1\n", 9, 11, "render.bounces");
    expectError(base + "lights = [ { type = \"environment\", direction = [0, -1, 0] } ]\n", 9, 48,
                "render.lights[1].direction: an environment light lights from every direction");
    const std::vector<Diagnostic> d = errors(base + "lights = [ { type = \"sky\" } ]\n");
    ASSERT_FALSE(d.empty());
    EXPECT_NE(d[0].message.find("directional, point, environment"), std::string::npos)
        << d[0].str();
}

TEST(Scene, ShadowCacheSpacing)
{
    EXPECT_EQ(parse(kMinimal).render.shadowCacheVoxels, 1); // the documented default
    const std::string base = std::string(kMinimal) + "[render]\n";
    EXPECT_EQ(parse(base + "shadow_cache = 0\n").render.shadowCacheVoxels, 0); // exact
    EXPECT_EQ(parse(base + "shadow_cache = 3\n").render.shadowCacheVoxels, 3);
    expectError(base + "shadow_cache = 17\n", 9, 16, "render.shadow_cache");
    expectError(base + "shadow_cache = 1.5\n", 9, 16, "render.shadow_cache");
}

TEST(Scene, PropsAreRead)
{
    const Scene s = parse(std::string(kMinimal) + R"(
[[prop]]
mesh = "meshes/cube.obj"
transform = { translate = [0, -1, 0], scale = [4, 0.1, 4] }
color = [0.2, 0.3, 0.4]
[[prop]]
mesh = "meshes/tetra.off"
shadow_catcher = true
[[prop]]
mesh = "meshes/tetra.off"
holdout = true
)");
    ASSERT_EQ(s.props.size(), 3u);
    EXPECT_EQ(s.props[0].mesh, kInline.parent_path() / "meshes/cube.obj");
    EXPECT_EQ(s.props[0].transform.translate, Vec3d(0, -1, 0));
    EXPECT_EQ(s.props[0].color, Vec3d(0.2, 0.3, 0.4));
    EXPECT_FALSE(s.props[0].holdout || s.props[0].shadowCatcher);
    EXPECT_EQ(s.props[1].color, Vec3d(0.8)); // the documented default
    EXPECT_TRUE(s.props[1].shadowCatcher);
    EXPECT_TRUE(s.props[2].holdout);
    EXPECT_EQ(s.props[1].where.line, 14);
}

TEST(SceneErrors, PropMistakes)
{
    expectAddedError("[[prop]]\ncolor = [0.5, 0.5, 0.5]\n", 8, 1, "missing prop[1].mesh");
    expectAddedError("[[prop]]\nmesh = \"meshes/cube.obj\"\nholdout = 1\n", 10, 11,
                     "prop[1].holdout: expected true or false");
    // Every problem of every prop at once.
    const std::vector<Diagnostic> both =
        errors(std::string(kMinimal) +
               "[[prop]]\nmesh = \"meshes/cube.obj\"\nshadow_catcher = true\nholdout = true\n"
               "[[prop]]\nmesh = \"meshes/none.obj\"\n");
    ASSERT_EQ(both.size(), 2u);
    EXPECT_NE(both[0].message.find("a holdout or a shadow catcher, not both"), std::string::npos);
    EXPECT_NE(both[1].message.find("prop[2].mesh: file not found"), std::string::npos);
    expectAddedError("[prop]\nmesh = \"meshes/cube.obj\"\n", 8, 1, "expected [[prop]] tables");
    expectAddedError("[[prop]]\nmesh = \"meshes/cube.obj\"\nshade = 1\n", 10, 1,
                     "unknown key 'shade' in [prop[1]]");
}
