#include "EditDocument.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/FileText.h>

#include <algorithm>

namespace volmorph::editor {
namespace {

using nlohmann::json;

/// Undo keeps this many steps (texts of a few KB each).
constexpr size_t kUndoSteps = 500;

double number(const json& value, const char* what)
{
    if (!value.is_number()) throw BadRequest(std::string(what) + ": expected a number");
    return value.get<double>();
}

/// [x, y, z] of numbers.
Vec3d vec3(const json& value, const char* what)
{
    if (!value.is_array() || value.size() != 3)
        throw BadRequest(std::string(what) + ": expected [x, y, z]");
    return Vec3d(number(value[0], what), number(value[1], what), number(value[2], what));
}

std::vector<double> numbers(const Vec3d& v)
{
    return {v.x(), v.y(), v.z()};
}

/// A pair's value as TOML text: `field` origin, axes, scale or type.
std::string tomlValue(const std::string& field, const json& value)
{
    if (field == "type") {
        if (!value.is_string()) throw BadRequest("type: expected a string");
        const std::string type = value.get<std::string>();
        for (const char* known : {"point", "segment", "rectangle", "box"})
            if (type == known) return "\"" + type + "\"";
        throw BadRequest("type: expected point, segment, rectangle or box");
    }
    if (field == "axes") {
        if (!value.is_array() || value.size() != 2) throw BadRequest("axes: expected [[x], [y]]");
        return "[" + tomlArray(numbers(vec3(value[0], "axes"))) + ", " +
               tomlArray(numbers(vec3(value[1], "axes"))) + "]";
    }
    if (field == "scale" && value.is_number()) return tomlNumber(value.get<double>());
    return tomlArray(numbers(vec3(value, field.c_str())));
}

int pairIndex(const json& body, int count)
{
    if (!body.is_object() || !body.contains("index") || !body["index"].is_number_integer())
        throw BadRequest("expected {\"index\": N}");
    const auto index = body["index"].get<long long>();
    if (index < 1 || index > count) throw BadRequest("no pair " + std::to_string(index));
    return int(index);
}

const std::string& action(const json& body, const char* key)
{
    if (!body.is_object() || !body.contains(key) || !body[key].is_string())
        throw BadRequest(std::string("expected a string \"") + key + "\"");
    return body[key].get_ref<const std::string&>();
}

/// The validator's errors, each placed at the pair (and side) whose lines hold it.
std::vector<PlacedError> place(const UserError& error,
                               const std::vector<SceneDocument::PairLines>& pairs)
{
    std::vector<PlacedError> placed;
    for (const Diagnostic& d : error.diagnostics()) {
        PlacedError e{d.where.str(), d.message, 0, ""};
        const int line = d.where.line;
        for (size_t i = 0; i < pairs.size(); ++i) {
            const SceneDocument::PairLines& p = pairs[i];
            if (line < p.header || line > p.last) continue;
            e.pair = int(i) + 1;
            if (line >= p.sourceFirst && line <= p.sourceLast) e.side = "source";
            if (line >= p.targetFirst && line <= p.targetLast) e.side = "target";
        }
        placed.push_back(std::move(e));
    }
    return placed;
}

FeaturePairSpec pairFromJson(const json& body)
{
    if (!body.is_object() || !body.contains("source") || !body.contains("target"))
        throw BadRequest("expected {\"type\", \"source\", \"target\"}");
    FeaturePairSpec pair;
    const std::string type = tomlValue("type", body.value("type", json()));
    pair.type = type == "\"point\""     ? FeatureType::Point
                : type == "\"segment\"" ? FeatureType::Segment
                : type == "\"box\""     ? FeatureType::Box
                                        : FeatureType::Rectangle;
    pair.source = elementFromJson(body["source"]);
    pair.target = elementFromJson(body["target"]);
    return pair;
}

bool sameElement(const FeatureElement& a, const FeatureElement& b)
{
    return a.origin == b.origin && a.xAxis == b.xAxis && a.yAxis == b.yAxis && a.scale == b.scale;
}

bool samePair(const FeaturePairSpec& a, const FeaturePairSpec& b)
{
    return a.type == b.type && sameElement(a.source, b.source) && sameElement(a.target, b.target);
}

json cameraJson(const RenderSpec& r)
{
    const CameraSpec& c = r.camera;
    return {{"eye", numbers(c.eye)},
            {"lookat", numbers(c.lookat)},
            {"up", numbers(c.up)},
            {"fov", c.fovDegrees},
            {"aspect", double(r.width) / double(r.height)}};
}

} // namespace

FeatureElement elementFromJson(const json& value)
{
    if (!value.is_object() || !value.contains("origin"))
        throw BadRequest("an element: expected {\"origin\": [x, y, z], ...}");
    FeatureElement e;
    e.origin = vec3(value["origin"], "origin");
    if (value.contains("axes")) {
        const json& axes = value["axes"];
        if (!axes.is_array() || axes.size() != 2) throw BadRequest("axes: expected [[x], [y]]");
        e.xAxis = vec3(axes[0], "axes");
        e.yAxis = vec3(axes[1], "axes");
        e.zAxis = e.xAxis.cross(e.yAxis);
    }
    if (value.contains("scale")) {
        const json& s = value["scale"];
        e.scale = s.is_number() ? Vec3d(number(s, "scale")) : vec3(s, "scale");
    }
    return e;
}

json elementToJson(const FeatureElement& e)
{
    return {{"origin", numbers(e.origin)},
            {"axes", {numbers(e.xAxis), numbers(e.yAxis)}},
            {"scale", numbers(e.scale)}};
}

EditDocument::EditDocument(std::filesystem::path scene)
    : mPath(std::move(scene)), mDocument(SceneDocument::read(mPath)), mSaved(mDocument.text()),
      mScene(parseScene(mDocument.text(), mPath))
{
}

namespace {

/// The pair (from 1) and the field ("type", "origin", "axes" or "scale") a key names:
/// pair[N].type or pair[N].source|target.origin|axes|scale; false for any other text.
bool parseKey(const std::string& key, long& pair, std::string& field)
{
    const std::string head = "pair[";
    const size_t close = key.find(']');
    if (key.size() > 40 || key.compare(0, head.size(), head) != 0 || close == std::string::npos)
        return false;
    const std::string digits = key.substr(head.size(), close - head.size());
    if (digits.empty() || digits.size() > 6 || digits[0] == '0' ||
        digits.find_first_not_of("0123456789") != std::string::npos)
        return false;
    pair = std::stol(digits);
    const std::string rest = key.substr(close + 1);
    if (rest == ".type") return field = "type", true;
    for (const char* side : {".source.", ".target."})
        for (const char* name : {"origin", "axes", "scale"})
            if (rest == std::string(side) + name) return field = name, true;
    return false;
}

/// The [timing] keys the page sets (the sweep it drags), as TOML text; empty for any other key.
std::string timingValue(const std::string& key, const json& value)
{
    if (key == "timing.spread" || key == "timing.sweep.length")
        return tomlNumber(number(value, key.c_str()));
    if (key == "timing.sweep.origin" || key == "timing.sweep.direction")
        return tomlArray(numbers(vec3(value, key.c_str())));
    return "";
}

/// One key set in `next`: a pair's value, or a timing key the file already has.
void setKey(const std::string& key, const json& value, SceneDocument& next)
{
    if (const std::string timing = timingValue(key, value); !timing.empty()) {
        try {
            next.set(key, timing);
        } catch (const std::invalid_argument& e) {
            throw BadRequest(key + ": the scene's [timing] has no such key to set (" + e.what() +
                             ")");
        }
        return;
    }
    long pair = 0;
    std::string field;
    if (!parseKey(key, pair, field))
        throw BadRequest("key \"" + key.substr(0, 80) +
                         "\": expected pair[N].type, pair[N].source|target.origin|axes|scale, "
                         "timing.spread or timing.sweep.origin|direction|length");
    if (const int count = next.pairCount(); pair > count)
        throw BadRequest("no pair " + std::to_string(pair) + " (the scene has " +
                         std::to_string(count) + ")");
    next.set(key, tomlValue(field, value));
}

bool sameTiming(const TimingSettings& a, const TimingSettings& b)
{
    if (a.spread != b.spread || a.sweep.has_value() != b.sweep.has_value()) return false;
    return !a.sweep ||
           (a.sweep->origin == b.sweep->origin && a.sweep->direction == b.sweep->direction &&
            a.sweep->length == b.sweep->length);
}

json timingJson(const Scene& scene)
{
    const TimingSettings& t = scene.timing;
    json sweep = nullptr;
    if (t.sweep)
        sweep = {{"origin", numbers(t.sweep->origin)},
                 {"direction", numbers(t.sweep->direction)},
                 {"length", t.sweep->length}};
    return {{"spread", t.spread}, {"sweep", sweep}, {"regions", scene.timingRegions.size()}};
}

} // namespace

void EditDocument::set(const json& body, SceneDocument& next) const
{
    if (body.is_object() && body.contains("values")) { // several keys, one step of undo
        const json& values = body["values"];
        if (!values.is_object() || values.empty() || values.size() > 16)
            throw BadRequest("values: expected {\"key\": value, ...}");
        for (const auto& [key, value] : values.items()) setKey(key, value, next);
        return;
    }
    const std::string& key = action(body, "key");
    if (!body.contains("value")) throw BadRequest("expected a \"value\"");
    setKey(key, body["value"], next);
}

void EditDocument::apply(const std::string& name, const json& body)
{
    if (name == "undo" || name == "redo") {
        std::vector<std::string>& from = name == "undo" ? mUndo : mRedo;
        std::vector<std::string>& to = name == "undo" ? mRedo : mUndo;
        if (from.empty()) throw BadRequest("nothing to " + name);
        to.push_back(mDocument.text());
        mDocument = SceneDocument(std::move(from.back()), mPath);
        from.pop_back();
        revalidate();
        return;
    }
    SceneDocument next = mDocument;
    try {
        if (name == "set") {
            set(body, next);
        } else if (name == "add") {
            next.appendPair(pairTableLines(pairFromJson(body)));
        } else if (name == "duplicate") {
            const int index = pairIndex(body, next.pairCount());
            if (!valid())
                throw Conflict("the scene has errors: fix or undo them before duplicating");
            next.appendPair(pairTableLines(mScene.pairs.at(size_t(index) - 1)));
        } else if (name == "delete") {
            next.removePair(pairIndex(body, next.pairCount()));
        } else {
            throw BadRequest("unknown edit \"" + name.substr(0, 40) + "\"");
        }
    } catch (const std::invalid_argument& e) {
        throw BadRequest(e.what()); // the edit would leave a file TOML cannot read
    }
    commit(std::move(next));
}

void EditDocument::appendPairs(const std::vector<FeaturePairSpec>& pairs,
                               const std::string& comment)
{
    SceneDocument next = mDocument;
    for (const FeaturePairSpec& pair : pairs) next.appendPair(pairTableLines(pair), {comment});
    commit(std::move(next));
}

void EditDocument::commit(SceneDocument next)
{
    mUndo.push_back(mDocument.text());
    if (mUndo.size() > kUndoSteps) mUndo.erase(mUndo.begin());
    mRedo.clear();
    mDocument = std::move(next);
    revalidate();
}

void EditDocument::revalidate()
{
    try {
        Scene scene = parseScene(mDocument.text(), mPath);
        mErrors.clear();
        const bool same =
            scene.pairs.size() == mScene.pairs.size() &&
            std::equal(scene.pairs.begin(), scene.pairs.end(), mScene.pairs.begin(), samePair);
        if (!same) ++mPairsVersion;
        if (!sameTiming(scene.timing, mScene.timing)) ++mTimingVersion;
        mScene = std::move(scene);
    } catch (const UserError& e) {
        mErrors = place(e, mDocument.pairLines());
    }
}

void EditDocument::save()
{
    if (!valid())
        throw Conflict("the scene has errors (" + mErrors.front().where + ": " +
                       mErrors.front().message + "): fix or undo them before saving");
    if (readFileText(mPath) != mSaved)
        throw Conflict(mPath.string() +
                       " changed on disk since the editor read it; not overwritten (restart the "
                       "editor to edit the new file)");
    mDocument.save(mPath);
    mSaved = mDocument.text();
}

json EditDocument::state() const
{
    json pairs = json::array();
    for (const FeaturePairSpec& p : mScene.pairs)
        pairs.push_back({{"type", toString(p.type)},
                         {"source", elementToJson(p.source)},
                         {"target", elementToJson(p.target)},
                         {"line", p.where.line}});
    json errors = json::array();
    for (const PlacedError& e : mErrors)
        errors.push_back(
            {{"where", e.where}, {"message", e.message}, {"pair", e.pair}, {"side", e.side}});
    return {{"scene", mPath.filename().string()},
            {"dirty", mDocument.text() != mSaved},
            {"canUndo", !mUndo.empty()},
            {"canRedo", !mRedo.empty()},
            {"valid", valid()},
            {"pairs", std::move(pairs)},
            {"errors", std::move(errors)},
            {"camera", cameraJson(mScene.render)},
            {"landmarks", mScene.blend.mode == BlendMode::Surface},
            {"timing", timingJson(mScene)}};
}

} // namespace volmorph::editor
