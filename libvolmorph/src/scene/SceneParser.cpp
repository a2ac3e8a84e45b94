// TOML scene file -> validated Scene.
//
// The parser keeps going after a problem so that every error in a file is reported at once, each at
// the line and column of the offending key or value (toml++ records both for every node). A TOML
// syntax error stops parsing: after one, toml++ has no tree to check.
#include <volmorph/Frames.h>
#include <volmorph/Scene.h>
#include <volmorph/core/FileText.h>

#include <optional>

#include "TableParsers.h"
#include "TomlReader.h"

#include <toml++/toml.h>

#include <cmath>
#include <limits>

namespace volmorph {
namespace {

using detail::formatNumber;
using detail::Reader;
using detail::typeName;

// Keys allowed at the root and in [frames]; each table group's are in its unit. Anything else is
// reported with a "did you mean" for near misses.
const std::vector<std::string> kRootKeys = {"source", "target", "volume",  "pair",
                                            "warp",   "blend",  "surface", "variational",
                                            "timing", "render", "prop",    "frames"};
const std::vector<std::string> kFramesKeys = {"range", "output", "fps"};

class SceneParser {
public:
    SceneParser(Reader& r, Scene& scene) : r(r), mScene(scene) {}

    void parse(const toml::table& root)
    {
        r.checkKeys(root, "", kRootKeys);

        if (const toml::node* n = root.get("source"))
            detail::parseObject(r, *n, "source", mScene.folder, mScene.source);
        else
            r.missingTable("source", "the mesh or volume the morph starts from");
        if (const toml::node* n = root.get("target"))
            detail::parseObject(r, *n, "target", mScene.folder, mScene.target);
        else
            r.missingTable("target", "the mesh or volume the morph ends at");

        if (const toml::node* n = root.get("volume"))
            detail::parseVolume(r, *n, mScene.volume);
        else if (!mScene.source.isVolume() && !mScene.target.isVolume())
            r.missingTable("volume", "voxel_size in world units, or resolution");
        // With a volume input and no [volume], the finest input's voxel size is the scene's.

        if (const toml::node* n = root.get("pair")) detail::parsePairs(r, *n, mScene.pairs);
        if (const toml::node* n = root.get("warp")) detail::parseWarp(r, *n, mScene.warp);
        if (const toml::node* n = root.get("blend")) detail::parseBlend(r, *n, mScene.blend);
        if (const toml::node* n = root.get("variational")) {
            detail::parseVariational(r, *n, mScene.folder, mScene.blend.variational,
                                     mScene.influences);
            if (mScene.blend.mode != BlendMode::Variational)
                r.error(r.at(*n), "[variational]: only used with blend.mode = \"variational\"");
        }
        if (const toml::node* n = root.get("surface")) {
            detail::parseSurface(r, *n, mScene.surface);
            if (mScene.blend.mode != BlendMode::Surface)
                r.error(r.at(*n), "[surface]: only used with blend.mode = \"surface\"");
        }
        if (mScene.blend.mode == BlendMode::Surface) checkSurfaceMode(root);
        if (const toml::node* n = root.get("timing")) {
            detail::parseTiming(r, *n, mScene.folder, mScene.timing, mScene.timingRegions);
        }
        if (const toml::node* n = root.get("render"))
            detail::parseRender(r, *n, mScene.folder, mScene.render);
        if (const toml::node* n = root.get("prop"))
            detail::parseProps(r, *n, mScene.folder, mScene.props);
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
    /// Surface mode morphs two meshes; its point pairs are landmarks, other pairs have no meaning.
    void checkSurfaceMode(const toml::table& root)
    {
        // Without a [surface] table its errors are the mode's: blend.mode = "surface".
        if (mScene.surface.where.file.empty())
            if (const toml::table* blend = root.get_as<toml::table>("blend"))
                if (const toml::node* mode = blend->get("mode")) mScene.surface.where = r.at(*mode);
        for (const ObjectSpec* side : {&mScene.source, &mScene.target})
            if (side->isVolume())
                r.error(side->fileWhere, "blend.mode = \"surface\" morphs two meshes; " +
                                             side->volume.filename().string() +
                                             " is a volume (use density, sdf or variational)");
        for (const FeaturePairSpec& p : mScene.pairs)
            if (p.type != FeatureType::Point)
                r.error(p.where, "[[pair]]: blend.mode = \"surface\" takes point pairs only "
                                 "(landmarks that meet)");
            else
                mScene.surface.landmarks.push_back({p.source.origin, p.target.origin, p.where});
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
        if (const toml::node* n = t->get("fps"))
            if (auto v = r.numberIn(*n, "frames.fps", 0.0, false, 10000.0,
                                    "frames per second, 0 < fps <= 10000"))
                f.fps = *v;
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
    const std::optional<std::string> text = readFileText(file);
    if (!text)
        throw UserError(SourceLocation{file.string()},
                        "cannot read scene file (expected a readable TOML file)");
    return parseScene(*text, file);
}

} // namespace volmorph
