// [render]: image, medium, camera and lights, with the keys that animate them.
#include "TableParsers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace volmorph::detail {
namespace {

const std::vector<std::string> kRenderKeys = {"resolution", "samples",    "step",    "extinction",
                                              "albedo",     "anisotropy", "seed",    "camera",
                                              "lights",     "emission",   "bounces", "shadow_cache",
                                              "shutter",    "layers",     "noise",   "denoise"};
const std::vector<std::string> kCameraKeys = {"projection", "eye",   "lookat", "up",
                                              "fov",        "width", "keys"};
const std::vector<std::string> kCameraKeyKeys = {"frame", "eye", "lookat", "up", "fov", "width"};
const std::vector<std::string> kLightKeys = {"type",      "direction", "position", "color",
                                             "intensity", "angle",     "map",      "keys"};
const std::vector<std::string> kLightKeyKeys = {"frame", "direction", "position", "color",
                                                "intensity"};

void checkView(Reader& r, const toml::node& where, const std::string& path, const Vec3d& eye,
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
void forEachKey(Reader& r, const toml::node& node, const std::string& path, F&& f)
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
            r.error(r.at(*frameNode),
                    keyPath +
                        ".frame: frames must increase from key to key (the key before is frame " +
                        std::to_string(*previous) + ")");
            continue;
        }
        previous = int(*frame);
        f(*k, item, keyPath, int(*frame));
    }
}

void parseCamera(Reader& r, const toml::node& node, CameraSpec& camera)
{
    const toml::table* t = r.table(node, "render.camera");
    if (!t) return;
    r.checkKeys(*t, "render.camera", kCameraKeys);
    CameraSpec& c = camera;
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
    checkView(r, node, "render.camera", c.eye, c.lookat, c.up);
    if (const toml::node* n = t->get("keys")) {
        forEachKey(
            r, *n, "render.camera.keys",
            [&](const toml::table& k, const toml::node& where, const std::string& path, int frame) {
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
                checkView(r, where, path, key.eye, key.lookat, key.up);
                if (!c.keys.empty() && key.up.unit().dot(c.keys.back().up.unit()) < -1.0 + 1e-9)
                    r.error(r.at(where), path + ".up: opposite to the previous key's up (the "
                                                "turn between them is undefined)");
                c.keys.push_back(key);
            });
    }
}

/// What a light of `type` is placed by: a directional light's direction, a point light's position,
/// nothing for an environment. `key` is the name of a key that may place a light.
std::string misplaced(LightType type, const std::string& key)
{
    if (type == LightType::Environment) return "an environment light lights from every direction";
    if (type == LightType::Point && key == "direction")
        return "a point light has a position, not a direction";
    if (type == LightType::Directional && key == "position")
        return "a directional light has a direction, not a position";
    return "";
}

/// Reads `key` ("direction" or "position") at `n` into `direction` or `position`, or reports that
/// a light of `type` has no such key.
void readPlacement(Reader& r, const toml::node& n, const std::string& path, const std::string& key,
                   LightType type, Vec3d& direction, Vec3d& position)
{
    const std::string why = misplaced(type, key);
    if (!why.empty()) {
        r.error(r.at(n), path + "." + key + ": " + why);
        return;
    }
    if (key == "direction") {
        if (auto v = r.direction(n, path + ".direction")) direction = *v;
    } else if (auto v = r.vec3(n, path + ".position")) {
        position = *v;
    }
}

/// The light's type and what places it (direction or position).
void parsePlacement(Reader& r, const toml::table& t, const toml::node& node,
                    const std::string& path, LightSpec& light)
{
    if (const toml::node* n = t.get("type")) {
        if (auto s = r.choice(*n, path + ".type", {"directional", "point", "environment"}))
            light.type = *s == "point"         ? LightType::Point
                         : *s == "environment" ? LightType::Environment
                                               : LightType::Directional;
    } else {
        r.missing(node, path + ".type", "directional, point or environment");
    }
    // The key that places this type first, then the one it must not have.
    const bool point = light.type == LightType::Point;
    for (const char* key : {point ? "position" : "direction", point ? "direction" : "position"}) {
        if (const toml::node* n = t.get(key))
            readPlacement(r, *n, path, key, light.type, light.direction, light.position);
        else if (misplaced(light.type, key).empty())
            r.missing(node, path + "." + key,
                      point ? "[x, y, z] in world units" : "the way the light travels, [x, y, z]");
    }
}

void parseLight(Reader& r, const toml::node& node, const std::string& path,
                const std::filesystem::path& folder, std::vector<LightSpec>& lights)
{
    const toml::table* t = r.table(node, path);
    if (!t) return;
    r.checkKeys(*t, path, kLightKeys);
    LightSpec light;
    parsePlacement(r, *t, node, path, light);
    if (const toml::node* n = t->get("color"))
        if (auto v = r.nonNegativeVec3(*n, path + ".color")) light.color = *v;
    if (const toml::node* n = t->get("intensity"))
        if (auto v = r.numberIn(*n, path + ".intensity", 0.0, true,
                                std::numeric_limits<double>::max(), "an intensity >= 0"))
            light.intensity = *v;
    if (const toml::node* n = t->get("angle")) {
        if (light.type != LightType::Directional)
            r.error(r.at(*n), path + ".angle: only a directional light has an angular diameter");
        else if (auto v = r.numberIn(*n, path + ".angle", 0.0, true, 180.0,
                                     "an angular diameter in degrees, from 0 to 180"))
            light.angleRadians = *v * kDegreesToRadians;
    }
    if (const toml::node* n = t->get("map")) {
        const bool another = std::any_of(lights.begin(), lights.end(),
                                         [](const LightSpec& l) { return !l.map.empty(); });
        if (light.type != LightType::Environment)
            r.error(r.at(*n), path + ".map: only an environment light has a sky map");
        else if (another)
            r.error(r.at(*n), path + ".map: only one environment light may have a map");
        else
            parseFile(r, *n, path + ".map", folder, light.map, light.mapWhere);
    }
    if (const toml::node* n = t->get("keys")) {
        forEachKey(
            r, *n, path + ".keys",
            [&](const toml::table& k, const toml::node& where, const std::string& keyPath,
                int frame) {
                r.checkKeys(k, keyPath, kLightKeyKeys);
                LightKey key{frame, light.direction, light.position, light.color, light.intensity};
                for (const char* placement : {"direction", "position"})
                    if (const toml::node* e = k.get(placement))
                        readPlacement(r, *e, keyPath, placement, light.type, key.direction,
                                      key.position);
                if (const toml::node* e = k.get("color"))
                    if (auto v = r.nonNegativeVec3(*e, keyPath + ".color")) key.color = *v;
                if (const toml::node* e = k.get("intensity"))
                    if (auto v =
                            r.numberIn(*e, keyPath + ".intensity", 0.0, true,
                                       std::numeric_limits<double>::max(), "an intensity >= 0"))
                        key.intensity = *v;
                if (!light.keys.empty() &&
                    key.direction.unit().dot(light.keys.back().direction.unit()) < -1.0 + 1e-9)
                    r.error(r.at(where), keyPath +
                                             ".direction: opposite to the previous key's direction "
                                             "(the turn between them is undefined)");
                light.keys.push_back(key);
            });
    }
    lights.push_back(light);
}

} // namespace

void parseRender(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                 RenderSpec& rs)
{
    const toml::table* t = r.table(node, "render");
    if (!t) return;
    r.checkKeys(*t, "render", kRenderKeys);

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
    if (const toml::node* n = t->get("noise"))
        if (auto v = r.numberIn(*n, "render.noise", 0.0, true, 1.0,
                                "a noise target from 0 (exactly `samples` samples) to 1, the "
                                "frame's relative RMSE"))
            rs.noise = *v;
    if (const toml::node* n = t->get("step"))
        if (auto v = r.numberIn(*n, "render.step", 0.0, false, 8.0,
                                "a ray-march step in voxels, 0 < step <= 8"))
            rs.stepVoxels = *v;
    if (const toml::node* n = t->get("extinction"))
        if (auto v =
                r.numberIn(*n, "render.extinction", 0.0, true, std::numeric_limits<double>::max(),
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
    if (const toml::node* n = t->get("bounces"))
        if (auto v = r.integerIn(*n, "render.bounces", 0, 100000)) rs.bounces = int(*v);
    if (const toml::node* n = t->get("shadow_cache"))
        if (auto v = r.integerIn(*n, "render.shadow_cache", 0, 16)) rs.shadowCacheVoxels = int(*v);
    if (const toml::node* n = t->get("emission"))
        if (auto v = r.nonNegativeVec3(*n, "render.emission")) rs.emission = *v;
    if (const toml::node* n = t->get("layers"))
        if (auto v = r.boolean(*n, "render.layers")) rs.layers = *v;
    if (const toml::node* n = t->get("denoise"))
        if (auto v = r.boolean(*n, "render.denoise")) rs.denoise = *v;
    if (const toml::node* n = t->get("shutter"))
        if (auto v = r.interval(*n, "render.shutter",
                                "the shutter's open and close in frames around the frame", false))
            rs.shutter = *v;
    if (const toml::node* n = t->get("camera")) parseCamera(r, *n, rs.camera);
    if (const toml::node* n = t->get("lights")) {
        if (const toml::array* a = n->as_array()) {
            for (size_t i = 0; i < a->size(); ++i)
                parseLight(r, *a->get(i), "render.lights[" + std::to_string(i + 1) + "]", folder,
                           rs.lights);
        } else {
            r.error(r.at(*n), "render.lights: expected an array of light tables, got " +
                                  std::string(typeName(*n)));
        }
    }
}

} // namespace volmorph::detail
