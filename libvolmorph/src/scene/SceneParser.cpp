// TOML scene file -> validated Scene.
//
// The parser keeps going after a problem so that every error in a file is reported at once, each at
// the line and column of the offending key or value (toml++ records both for every node). A TOML
// syntax error stops parsing: after one, toml++ has no tree to check.
#include <volmorph/Frames.h>
#include <volmorph/Scene.h>

#include <optional>

#include "TomlReader.h"

#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace volmorph {
namespace {

using detail::formatNumber;
using detail::Reader;
using detail::typeName;

constexpr double kDegreesToRadians = 3.14159265358979323846 / 180.0;

// Keys allowed in each table; anything else is reported with a "did you mean" for near misses.
const std::vector<std::string> kRootKeys = {"source", "target", "volume", "pair",
                                            "warp",   "blend",  "render", "frames"};
const std::vector<std::string> kObjectKeys = {"mesh", "transform", "color"};
const std::vector<std::string> kTransformKeys = {"translate", "rotate", "scale"};
const std::vector<std::string> kVolumeKeys = {"voxel_size", "resolution"};
const std::vector<std::string> kPairKeys = {"type", "source", "target"};
const std::vector<std::string> kElementKeys = {"origin", "axes", "scale"};
const std::vector<std::string> kWarpKeys = {"epsilon", "tolerance", "weighting", "a", "b", "p"};
const std::vector<std::string> kBlendKeys = {"mode", "density", "color", "sdf", "min_island"};
const std::vector<std::string> kRenderKeys = {"resolution", "samples",    "step", "extinction",
                                              "albedo",     "anisotropy", "seed", "camera",
                                              "lights",     "emission"};
const std::vector<std::string> kCameraKeys = {"projection", "eye",   "lookat", "up",
                                              "fov",        "width", "keys"};
const std::vector<std::string> kCameraKeyKeys = {"frame", "eye", "lookat", "up", "fov", "width"};
const std::vector<std::string> kLightKeys = {"type",  "direction", "position",
                                             "color", "intensity", "keys"};
const std::vector<std::string> kLightKeyKeys = {"frame", "direction", "position", "color",
                                                "intensity"};
const std::vector<std::string> kFramesKeys = {"range", "output"};

// ------------------------------------------------------------------------------------------------

class SceneParser {
public:
    SceneParser(Reader& r, Scene& scene) : r(r), mScene(scene) {}

    void parse(const toml::table& root)
    {
        r.checkKeys(root, "", kRootKeys);

        if (const toml::node* n = root.get("source"))
            parseObject(*n, "source", mScene.source);
        else
            r.missingTable("source", "the mesh the morph starts from");
        if (const toml::node* n = root.get("target"))
            parseObject(*n, "target", mScene.target);
        else
            r.missingTable("target", "the mesh the morph ends at");

        if (const toml::node* n = root.get("volume"))
            parseVolume(*n);
        else
            r.missingTable("volume", "voxel_size in world units, or resolution");

        if (const toml::node* n = root.get("pair")) parsePairs(*n);
        if (const toml::node* n = root.get("warp")) parseWarp(*n);
        if (const toml::node* n = root.get("blend")) parseBlend(*n);
        if (const toml::node* n = root.get("render")) parseRender(*n);
        if (mScene.render.lights.empty()) {
            // Default: a white key light from above, front-left.
            LightSpec key;
            key.direction = Vec3d(0.5, -1.0, -0.5).unit();
            key.intensity = 3.0;
            mScene.render.lights.push_back(key);
        }
        if (const toml::node* n = root.get("frames")) parseFrames(*n);
    }

private:
    void parseObject(const toml::node& node, const std::string& path, ObjectSpec& object)
    {
        const toml::table* t = r.table(node, path);
        if (!t) return;
        r.checkKeys(*t, path, kObjectKeys);
        if (const toml::node* n = t->get("mesh")) {
            if (auto s = r.string(*n, path + ".mesh")) {
                object.meshWhere = r.at(*n);
                std::filesystem::path p(*s);
                object.mesh = p.is_absolute() ? p : mScene.folder / p;
                std::error_code ec;
                if (s->empty())
                    r.error(r.at(*n), path + ".mesh: expected a file name");
                else if (!std::filesystem::is_regular_file(object.mesh, ec))
                    r.error(r.at(*n), path + ".mesh: file not found: '" + *s + "' (looked for " +
                                          object.mesh.string() + ")");
            }
        } else {
            r.missing(node, path + ".mesh", "a mesh file name, relative to the scene file");
        }
        if (const toml::node* n = t->get("transform"))
            parseTransform(*n, path + ".transform", object.transform);
        if (const toml::node* n = t->get("color"))
            if (auto c = r.nonNegativeVec3(*n, path + ".color")) object.color = *c;
    }

    void parseTransform(const toml::node& node, const std::string& path, ObjectTransform& xf)
    {
        const toml::table* t = r.table(node, path);
        if (!t) return;
        r.checkKeys(*t, path, kTransformKeys);
        if (const toml::node* n = t->get("translate"))
            if (auto v = r.vec3(*n, path + ".translate")) xf.translate = *v;
        if (const toml::node* n = t->get("rotate"))
            if (auto v = r.vec3(*n, path + ".rotate")) xf.rotateRadians = *v * kDegreesToRadians;
        if (const toml::node* n = t->get("scale")) {
            if (n->is_array()) {
                if (auto v = r.positiveVec3(*n, path + ".scale", "a factor")) xf.scale = *v;
            } else if (auto s = r.numberIn(*n, path + ".scale", 0.0, false,
                                           std::numeric_limits<double>::max(),
                                           "a positive factor or an array of 3")) {
                xf.scale = Vec3d(*s);
            }
        }
    }

    void parseVolume(const toml::node& node)
    {
        const toml::table* t = r.table(node, "volume");
        if (!t) return;
        r.checkKeys(*t, "volume", kVolumeKeys);
        const toml::node* size = t->get("voxel_size");
        const toml::node* res = t->get("resolution");
        if (size && res) {
            r.error(r.at(*res), "volume: give either voxel_size or resolution, not both");
        } else if (size) {
            mScene.volume.voxelSize =
                r.numberIn(*size, "volume.voxel_size", 0.0, false,
                           std::numeric_limits<double>::max(), "a positive length in world units");
        } else if (res) {
            if (auto v = r.integerIn(*res, "volume.resolution", 8, 16384))
                mScene.volume.resolution = int(*v);
        } else {
            r.missing(node, "volume.voxel_size",
                      "a positive length in world units, or resolution in voxels");
        }
    }

    void parsePairs(const toml::node& node)
    {
        const toml::array* pairs = node.as_array();
        if (!pairs) {
            r.error(r.at(node),
                    "pair: expected [[pair]] tables, got " + std::string(typeName(node)));
            return;
        }
        for (size_t i = 0; i < pairs->size(); ++i) {
            const std::string path = "pair[" + std::to_string(i + 1) + "]";
            if (const toml::table* t = r.table(*pairs->get(i), path)) parsePair(*t, path);
        }
    }

    void parsePair(const toml::table& t, const std::string& path)
    {
        r.checkKeys(t, path, kPairKeys);
        FeaturePairSpec pair;
        pair.where = r.at(t);
        bool ok = true;
        if (const toml::node* n = t.get("type")) {
            const auto s = r.choice(*n, path + ".type", {"point", "segment", "rectangle", "box"});
            if (!s)
                ok = false;
            else if (*s == "point")
                pair.type = FeatureType::Point;
            else if (*s == "segment")
                pair.type = FeatureType::Segment;
            else if (*s == "rectangle")
                pair.type = FeatureType::Rectangle;
            else
                pair.type = FeatureType::Box;
        } else {
            r.missing(t, path + ".type", "point, segment, rectangle or box");
            ok = false;
        }
        for (const char* side : {"source", "target"}) {
            FeatureElement& element = std::string(side) == "source" ? pair.source : pair.target;
            if (const toml::node* n = t.get(side)) {
                ok = parseElement(*n, path + "." + side, pair.type, element) && ok;
            } else {
                r.missing(t, path + "." + side, "a table with origin, axes and scale");
                ok = false;
            }
        }
        if (ok) mScene.pairs.push_back(pair);
    }

    bool parseElement(const toml::node& node, const std::string& path, FeatureType type,
                      FeatureElement& e)
    {
        const toml::table* t = r.table(node, path);
        if (!t) return false;
        const size_t before = r.diagnostics().size();
        r.checkKeys(*t, path, kElementKeys);
        if (const toml::node* n = t->get("origin")) {
            if (auto v = r.vec3(*n, path + ".origin")) e.origin = *v;
        } else {
            r.missing(node, path + ".origin", "[x, y, z] in world units");
        }
        const bool isPoint = type == FeatureType::Point;
        if (const toml::node* n = t->get("axes"))
            parseAxes(*n, path + ".axes", e);
        else if (!isPoint)
            r.missing(node, path + ".axes", "[[x axis], [y axis]]; z is x cross y");
        if (const toml::node* n = t->get("scale")) {
            if (auto v = r.positiveVec3(*n, path + ".scale", "world units")) e.scale = *v;
        } else if (!isPoint) {
            r.missing(node, path + ".scale", "[sx, sy, sz] in world units, each > 0");
        }
        return r.diagnostics().size() == before;
    }

    void parseAxes(const toml::node& node, const std::string& path, FeatureElement& e)
    {
        const toml::array* a = node.as_array();
        if (!a || a->size() != 2) {
            r.error(r.at(node),
                    path + ": expected two axes [[x], [y]], got " +
                        (a ? "an array of " + std::to_string(a->size()) : typeName(node)));
            return;
        }
        const std::optional<Vec3d> x = r.vec3(*a->get(0), path + "[0]");
        const std::optional<Vec3d> y = r.vec3(*a->get(1), path + "[1]");
        if (!x || !y) return;
        if (x->length() < 1e-12 || y->length() < 1e-12) {
            r.error(r.at(x->length() < 1e-12 ? *a->get(0) : *a->get(1)),
                    path + ": an axis has zero length");
            return;
        }
        const Vec3d xu = x->unit(), yu = y->unit();
        const double cosine = std::abs(xu.dot(yu));
        // Hand-typed axes are often slightly off; within 5 degrees of perpendicular is corrected by
        // Gram-Schmidt (x kept, y adjusted), more than that is almost certainly a mistake.
        const double kMaxCosine = std::sin(5.0 * kDegreesToRadians);
        if (cosine > 1.0 - 1e-9) {
            r.error(r.at(node),
                    path + ": the x and y axes are parallel; they must be perpendicular");
            return;
        }
        if (cosine > kMaxCosine) {
            // Tenths of a degree: hand-typed axes are not more precise than that.
            const double angle = std::round(10.0 * std::acos(std::clamp(xu.dot(yu), -1.0, 1.0)) /
                                            kDegreesToRadians) /
                                 10.0;
            r.error(r.at(node), path +
                                    ": the x and y axes must be perpendicular (within 5 degrees); "
                                    "they are " +
                                    formatNumber(angle) + " degrees apart");
            return;
        }
        e.xAxis = xu;
        e.yAxis = (yu - xu * xu.dot(yu)).unit();
        e.zAxis = e.xAxis.cross(e.yAxis);
    }

    void parseWarp(const toml::node& node)
    {
        const toml::table* t = r.table(node, "warp");
        if (!t) return;
        r.checkKeys(*t, "warp", kWarpKeys);
        WarpSpec& w = mScene.warp;
        const double big = std::numeric_limits<double>::max();
        if (const toml::node* n = t->get("epsilon"))
            if (auto v =
                    r.numberIn(*n, "warp.epsilon", 0.0, true, big, "a length >= 0 in world units"))
                w.epsilon = *v;
        if (const toml::node* n = t->get("tolerance"))
            if (auto v = r.numberIn(*n, "warp.tolerance", 0.0, true, 64.0,
                                    "a tolerance from 0 (exact) to 64 voxels"))
                w.toleranceVoxels = *v;
        if (const toml::node* n = t->get("weighting"))
            if (auto s = r.choice(*n, "warp.weighting", {"inverse-square", "beier-neely"}))
                w.weighting =
                    *s == "beier-neely" ? Weighting::BeierNeely : Weighting::InverseSquare;
        if (const toml::node* n = t->get("a"))
            if (auto v = r.numberIn(*n, "warp.a", 0.0, false, big, "a length > 0 in world units"))
                w.a = *v;
        if (const toml::node* n = t->get("b"))
            if (auto v = r.numberIn(*n, "warp.b", 0.0, true, 16.0, "an exponent from 0 to 16"))
                w.b = *v;
        if (const toml::node* n = t->get("p"))
            if (auto v = r.numberIn(*n, "warp.p", 0.0, true, 1.0, "an exponent from 0 to 1"))
                w.p = *v;
        if (w.weighting == Weighting::InverseSquare)
            for (const char* k : {"a", "b", "p"})
                if (const toml::node* n = t->get(k))
                    r.error(r.at(*n), std::string("warp.") + k +
                                          ": only used with weighting = \"beier-neely\"");
    }

    void parseSchedule(const toml::node& node, const std::string& path, ScheduleSpec& s)
    {
        if (const auto* str = node.as_string()) {
            const std::string& text = str->get();
            if (text == "linear")
                s.kind = ScheduleSpec::Kind::Linear;
            else if (text == "smoothstep")
                s.kind = ScheduleSpec::Kind::Smoothstep;
            else if (text.rfind("sigmoid(", 0) == 0 && text.back() == ')') {
                const std::string arg = text.substr(8, text.size() - 9);
                char* end = nullptr;
                const double k = std::strtod(arg.c_str(), &end);
                if (arg.empty() || *end != '\0' || !std::isfinite(k) || k <= 0.0 || k > 1000.0)
                    r.error(r.at(node), path +
                                            ": sigmoid(k) needs a steepness 0 < k <= 1000, got \"" +
                                            text + "\"");
                s.kind = ScheduleSpec::Kind::Sigmoid;
                s.k = k;
            } else {
                r.error(r.at(node), path + ": unknown schedule \"" + text +
                                        "\"; expected linear, smoothstep, sigmoid(k) or an array "
                                        "of [t, tau] points");
            }
            return;
        }
        const toml::array* a = node.as_array();
        if (!a) {
            r.error(r.at(node),
                    path + ": expected a schedule name or an array of [t, tau] points, got " +
                        typeName(node));
            return;
        }
        std::vector<std::pair<double, double>> points;
        for (size_t i = 0; i < a->size(); ++i) {
            const toml::node& p = *a->get(i);
            const toml::array* pt = p.as_array();
            const std::string ppath = path + "[" + std::to_string(i) + "]";
            if (!pt || pt->size() != 2) {
                r.error(r.at(p), ppath + ": expected a point [t, tau]");
                return;
            }
            const auto t = r.numberIn(*pt->get(0), ppath + " t", 0.0, true, 1.0, "t from 0 to 1");
            const auto tau =
                r.numberIn(*pt->get(1), ppath + " tau", 0.0, true, 1.0, "tau from 0 to 1");
            if (!t || !tau) return;
            if (!points.empty() && *t <= points.back().first) {
                r.error(r.at(p), ppath + ": t must increase from point to point");
                return;
            }
            if (!points.empty() && *tau < points.back().second) {
                r.error(r.at(p), ppath + ": tau must not decrease (a schedule is monotone)");
                return;
            }
            points.emplace_back(*t, *tau);
        }
        if (points.size() < 2 || points.front() != std::make_pair(0.0, 0.0) ||
            points.back() != std::make_pair(1.0, 1.0)) {
            r.error(r.at(node), path +
                                    ": a curve needs at least two points, starting at [0, 0] and "
                                    "ending at [1, 1]");
            return;
        }
        s.kind = ScheduleSpec::Kind::Curve;
        s.points = std::move(points);
    }

    void parseBlend(const toml::node& node)
    {
        const toml::table* t = r.table(node, "blend");
        if (!t) return;
        r.checkKeys(*t, "blend", kBlendKeys);
        BlendSpec& b = mScene.blend;
        if (const toml::node* n = t->get("mode"))
            if (auto s = r.choice(*n, "blend.mode", {"density", "sdf"}))
                b.mode = *s == "sdf" ? BlendMode::Sdf : BlendMode::Density;
        if (const toml::node* n = t->get("density")) parseSchedule(*n, "blend.density", b.density);
        if (const toml::node* n = t->get("color")) parseSchedule(*n, "blend.color", b.color);
        if (const toml::node* n = t->get("sdf")) parseSchedule(*n, "blend.sdf", b.sdf);
        if (const toml::node* n = t->get("min_island"))
            if (auto v = r.integerIn(*n, "blend.min_island", 0, 1000000000))
                b.minIslandVoxels = int(*v);
    }

    void parseCamera(const toml::node& node)
    {
        const toml::table* t = r.table(node, "render.camera");
        if (!t) return;
        r.checkKeys(*t, "render.camera", kCameraKeys);
        CameraSpec& c = mScene.render.camera;
        if (const toml::node* n = t->get("projection"))
            if (auto s = r.choice(*n, "render.camera.projection", {"perspective", "orthographic"}))
                c.projection =
                    *s == "orthographic" ? Projection::Orthographic : Projection::Perspective;
        if (const toml::node* n = t->get("eye"))
            if (auto v = r.vec3(*n, "render.camera.eye")) c.eye = *v;
        if (const toml::node* n = t->get("lookat"))
            if (auto v = r.vec3(*n, "render.camera.lookat")) c.lookat = *v;
        if (const toml::node* n = t->get("up"))
            if (auto v = r.direction(*n, "render.camera.up")) c.up = *v;
        if (const toml::node* n = t->get("fov"))
            if (auto v = r.numberIn(*n, "render.camera.fov", 0.0, false, 179.0,
                                    "a horizontal field of view in degrees, 0 < fov <= 179"))
                c.fovDegrees = *v;
        if (const toml::node* n = t->get("width"))
            if (auto v = r.numberIn(*n, "render.camera.width", 0.0, false,
                                    std::numeric_limits<double>::max(),
                                    "an orthographic width > 0 in world units"))
                c.orthoWidth = *v;
        checkView(node, "render.camera", c.eye, c.lookat, c.up);
        if (const toml::node* n = t->get("keys")) {
            forEachKey(
                *n, "render.camera.keys",
                [&](const toml::table& k, const toml::node& where, const std::string& path,
                    int frame) {
                    r.checkKeys(k, path, kCameraKeyKeys);
                    CameraKey key{frame, c.eye, c.lookat, c.up, c.fovDegrees, c.orthoWidth};
                    if (const toml::node* e = k.get("eye"))
                        if (auto v = r.vec3(*e, path + ".eye")) key.eye = *v;
                    if (const toml::node* e = k.get("lookat"))
                        if (auto v = r.vec3(*e, path + ".lookat")) key.lookat = *v;
                    if (const toml::node* e = k.get("up"))
                        if (auto v = r.direction(*e, path + ".up")) key.up = *v;
                    if (const toml::node* e = k.get("fov"))
                        if (auto v =
                                r.numberIn(*e, path + ".fov", 0.0, false, 179.0,
                                           "a horizontal field of view in degrees, 0 < fov <= 179"))
                            key.fovDegrees = *v;
                    if (const toml::node* e = k.get("width"))
                        if (auto v = r.numberIn(*e, path + ".width", 0.0, false,
                                                std::numeric_limits<double>::max(),
                                                "an orthographic width > 0 in world units"))
                            key.orthoWidth = *v;
                    checkView(where, path, key.eye, key.lookat, key.up);
                    if (!c.keys.empty() && key.up.unit().dot(c.keys.back().up.unit()) < -1.0 + 1e-9)
                        r.error(r.at(where), path + ".up: opposite to the previous key's up (the "
                                                    "turn between them is undefined)");
                    c.keys.push_back(key);
                });
        }
    }

    void checkView(const toml::node& where, const std::string& path, const Vec3d& eye,
                   const Vec3d& lookat, const Vec3d& up)
    {
        const Vec3d view = lookat - eye;
        if (view.length() < 1e-12) {
            r.error(r.at(where), path + ": eye and lookat are the same point");
        } else if (std::abs(view.unit().dot(up.unit())) > 1.0 - 1e-9) {
            r.error(r.at(where), path + ": up is parallel to the view direction (eye to lookat)");
        }
    }

    /// Calls f(table, node, path, frame) for each key table of the array `node`, checking that
    /// every key has an integer frame and that frames increase.
    template <typename F>
    void forEachKey(const toml::node& node, const std::string& path, F&& f)
    {
        const toml::array* a = node.as_array();
        if (!a || a->empty()) {
            r.error(r.at(node), path + ": expected an array of key tables, each with a frame");
            return;
        }
        std::optional<int> previous;
        for (size_t i = 0; i < a->size(); ++i) {
            const std::string keyPath = path + "[" + std::to_string(i + 1) + "]";
            const toml::node& item = *a->get(i);
            const toml::table* k = r.table(item, keyPath);
            if (!k) continue;
            const toml::node* frameNode = k->get("frame");
            if (!frameNode) {
                r.missing(item, keyPath + ".frame", "the frame number of this key");
                continue;
            }
            const auto frame = r.integerIn(*frameNode, keyPath + ".frame", -100000000, 100000000);
            if (!frame) continue;
            if (previous && *frame <= *previous) {
                r.error(
                    r.at(*frameNode),
                    keyPath +
                        ".frame: frames must increase from key to key (the key before is frame " +
                        std::to_string(*previous) + ")");
                continue;
            }
            previous = int(*frame);
            f(*k, item, keyPath, int(*frame));
        }
    }

    void parseLight(const toml::node& node, const std::string& path)
    {
        const toml::table* t = r.table(node, path);
        if (!t) return;
        r.checkKeys(*t, path, kLightKeys);
        LightSpec light;
        if (const toml::node* n = t->get("type")) {
            if (auto s = r.choice(*n, path + ".type", {"directional", "point"}))
                light.type = *s == "point" ? LightType::Point : LightType::Directional;
        } else {
            r.missing(node, path + ".type", "directional or point");
        }
        if (light.type == LightType::Directional) {
            if (const toml::node* n = t->get("direction")) {
                if (auto v = r.direction(*n, path + ".direction")) light.direction = *v;
            } else {
                r.missing(node, path + ".direction", "the way the light travels, [x, y, z]");
            }
            if (const toml::node* n = t->get("position"))
                r.error(r.at(*n),
                        path + ".position: a directional light has a direction, not a position");
        } else {
            if (const toml::node* n = t->get("position")) {
                if (auto v = r.vec3(*n, path + ".position")) light.position = *v;
            } else {
                r.missing(node, path + ".position", "[x, y, z] in world units");
            }
            if (const toml::node* n = t->get("direction"))
                r.error(r.at(*n),
                        path + ".direction: a point light has a position, not a direction");
        }
        if (const toml::node* n = t->get("color"))
            if (auto v = r.nonNegativeVec3(*n, path + ".color")) light.color = *v;
        if (const toml::node* n = t->get("intensity"))
            if (auto v = r.numberIn(*n, path + ".intensity", 0.0, true,
                                    std::numeric_limits<double>::max(), "an intensity >= 0"))
                light.intensity = *v;
        if (const toml::node* n = t->get("keys")) {
            forEachKey(
                *n, path + ".keys",
                [&](const toml::table& k, const toml::node& where, const std::string& keyPath,
                    int frame) {
                    r.checkKeys(k, keyPath, kLightKeyKeys);
                    LightKey key{frame, light.direction, light.position, light.color,
                                 light.intensity};
                    if (const toml::node* e = k.get("direction")) {
                        if (light.type != LightType::Directional)
                            r.error(
                                r.at(*e),
                                keyPath +
                                    ".direction: a point light has a position, not a direction");
                        else if (auto v = r.direction(*e, keyPath + ".direction"))
                            key.direction = *v;
                    }
                    if (const toml::node* e = k.get("position")) {
                        if (light.type != LightType::Point)
                            r.error(r.at(*e), keyPath + ".position: a directional light has a "
                                                        "direction, not a position");
                        else if (auto v = r.vec3(*e, keyPath + ".position"))
                            key.position = *v;
                    }
                    if (const toml::node* e = k.get("color"))
                        if (auto v = r.nonNegativeVec3(*e, keyPath + ".color")) key.color = *v;
                    if (const toml::node* e = k.get("intensity"))
                        if (auto v =
                                r.numberIn(*e, keyPath + ".intensity", 0.0, true,
                                           std::numeric_limits<double>::max(), "an intensity >= 0"))
                            key.intensity = *v;
                    if (!light.keys.empty() &&
                        key.direction.unit().dot(light.keys.back().direction.unit()) < -1.0 + 1e-9)
                        r.error(r.at(where),
                                keyPath + ".direction: opposite to the previous key's direction "
                                          "(the turn between them is undefined)");
                    light.keys.push_back(key);
                });
        }
        mScene.render.lights.push_back(light);
    }

    void parseRender(const toml::node& node)
    {
        const toml::table* t = r.table(node, "render");
        if (!t) return;
        r.checkKeys(*t, "render", kRenderKeys);
        RenderSpec& rs = mScene.render;
        if (const toml::node* n = t->get("resolution")) {
            const toml::array* a = n->as_array();
            if (!a || a->size() != 2) {
                r.error(r.at(*n), "render.resolution: expected [width, height] in pixels");
            } else {
                const auto w = r.integerIn(*a->get(0), "render.resolution width", 1, 16384);
                const auto h = r.integerIn(*a->get(1), "render.resolution height", 1, 16384);
                if (w && h) {
                    rs.width = int(*w);
                    rs.height = int(*h);
                }
            }
        }
        if (const toml::node* n = t->get("samples"))
            if (auto v = r.integerIn(*n, "render.samples", 1, 65536)) rs.samples = int(*v);
        if (const toml::node* n = t->get("step"))
            if (auto v = r.numberIn(*n, "render.step", 0.0, false, 8.0,
                                    "a ray-march step in voxels, 0 < step <= 8"))
                rs.stepVoxels = *v;
        if (const toml::node* n = t->get("extinction"))
            if (auto v = r.numberIn(*n, "render.extinction", 0.0, true,
                                    std::numeric_limits<double>::max(),
                                    "an extinction >= 0 per world unit at density 1"))
                rs.extinction = *v;
        if (const toml::node* n = t->get("albedo"))
            if (auto v = r.numberIn(*n, "render.albedo", 0.0, true, 1.0, "an albedo from 0 to 1"))
                rs.albedo = *v;
        if (const toml::node* n = t->get("anisotropy"))
            if (auto v = r.numberIn(*n, "render.anisotropy", -1.0, false, 0.999,
                                    "a Henyey-Greenstein g with -1 < g < 1"))
                rs.anisotropy = *v;
        if (const toml::node* n = t->get("seed"))
            if (auto v = r.integerIn(*n, "render.seed", 0, std::numeric_limits<uint32_t>::max()))
                rs.seed = unsigned(*v);
        if (const toml::node* n = t->get("emission"))
            if (auto v = r.nonNegativeVec3(*n, "render.emission")) rs.emission = *v;
        if (const toml::node* n = t->get("camera")) parseCamera(*n);
        if (const toml::node* n = t->get("lights")) {
            if (const toml::array* a = n->as_array()) {
                for (size_t i = 0; i < a->size(); ++i)
                    parseLight(*a->get(i), "render.lights[" + std::to_string(i + 1) + "]");
            } else {
                r.error(r.at(*n), "render.lights: expected an array of light tables, got " +
                                      std::string(typeName(*n)));
            }
        }
    }

    void parseFrames(const toml::node& node)
    {
        const toml::table* t = r.table(node, "frames");
        if (!t) return;
        r.checkKeys(*t, "frames", kFramesKeys);
        FramesSpec& f = mScene.frames;
        if (const toml::node* n = t->get("range")) {
            if (auto s = r.string(*n, "frames.range"))
                if (!parseFrameRange(*s, f.first, f.last))
                    r.error(r.at(*n), "frames.range: expected \"FIRST-LAST\" with FIRST <= LAST "
                                      "(e.g. \"1-48\") or one frame \"N\", got \"" +
                                          *s + "\"");
        }
        if (const toml::node* n = t->get("output")) {
            if (auto s = r.string(*n, "frames.output")) {
                f.output = *s;
                f.outputWhere = r.at(*n);
            }
        }
        const bool hasPlaceholder =
            f.output.find('#') != std::string::npos || f.output.find('%') != std::string::npos;
        const SourceLocation where = f.outputWhere.line > 0 ? f.outputWhere : r.at(node);
        if (f.count() > 1 && !hasPlaceholder)
            r.error(where, "frames.output: \"" + f.output +
                               "\" has no frame number placeholder "
                               "(#### or %04d) for a range of " +
                               std::to_string(f.count()) + " frames");
        if (const std::string why = checkFramePattern(f.output); !why.empty())
            r.error(where, "frames.output: \"" + f.output + "\": " + why);
        if (std::filesystem::path(f.output).extension() != ".exr")
            r.error(where,
                    "frames.output: expected a file name ending in .exr, got \"" + f.output + "\"");
    }

    Reader& r;
    Scene& mScene;
};

bool parseInt(std::string_view text, int& value)
{
    if (text.empty() || text.size() > 10) return false;
    size_t i = 0;
    const bool negative = text[0] == '-';
    if (negative) ++i;
    if (i == text.size()) return false;
    long long v = 0;
    for (; i < text.size(); ++i) {
        if (text[i] < '0' || text[i] > '9') return false;
        v = v * 10 + (text[i] - '0');
    }
    value = int(negative ? -v : v);
    return true;
}

} // namespace

bool parseFrameRange(std::string_view text, int& first, int& last)
{
    // The separator is the first '-' that is not a leading sign.
    const size_t dash = text.find('-', 1);
    int a = 0, b = 0;
    if (dash == std::string_view::npos) {
        if (!parseInt(text, a)) return false;
        b = a;
    } else if (!parseInt(text.substr(0, dash), a) || !parseInt(text.substr(dash + 1), b)) {
        return false;
    }
    if (a > b) return false;
    first = a;
    last = b;
    return true;
}

Scene parseScene(std::string_view text, const std::filesystem::path& file)
{
    Scene scene;
    scene.file = file;
    scene.folder = file.parent_path();
    Reader reader(file.string());

    toml::table root;
    try {
        root = toml::parse(text, file.string());
    } catch (const toml::parse_error& e) {
        throw UserError(reader.at(e.source()),
                        "TOML syntax error: " + std::string(e.description()));
    }
    SceneParser(reader, scene).parse(root);
    reader.diagnostics().throwIfAny();
    return scene;
}

Scene loadScene(const std::filesystem::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec) || !in)
        throw UserError(SourceLocation{file.string()},
                        "cannot read scene file (expected a readable TOML file)");
    std::ostringstream text;
    text << in.rdbuf();
    return parseScene(text.str(), file);
}

} // namespace volmorph
