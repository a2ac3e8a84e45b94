// [[pair]]: feature pairs, each a type and two elements (origin, axes, scale).
#include "TableParsers.h"

#include <algorithm>
#include <cmath>

namespace volmorph::detail {
namespace {

const std::vector<std::string> kPairKeys = {"type", "source", "target"};
const std::vector<std::string> kElementKeys = {"origin", "axes", "scale"};

void parseAxes(Reader& r, const toml::node& node, const std::string& path, FeatureElement& e)
{
    const toml::array* a = node.as_array();
    if (!a || a->size() != 2) {
        r.error(r.at(node), path + ": expected two axes [[x], [y]], got " +
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
        r.error(r.at(node), path + ": the x and y axes are parallel; they must be perpendicular");
        return;
    }
    if (cosine > kMaxCosine) {
        // Tenths of a degree: hand-typed axes are not more precise than that.
        const double angle =
            std::round(10.0 * std::acos(std::clamp(xu.dot(yu), -1.0, 1.0)) / kDegreesToRadians) /
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

bool parseElement(Reader& r, const toml::node& node, const std::string& path, FeatureType type,
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
        parseAxes(r, *n, path + ".axes", e);
    else if (!isPoint)
        r.missing(node, path + ".axes", "[[x axis], [y axis]]; z is x cross y");
    if (const toml::node* n = t->get("scale")) {
        if (auto v = r.positiveVec3(*n, path + ".scale", "world units")) e.scale = *v;
    } else if (!isPoint) {
        r.missing(node, path + ".scale", "[sx, sy, sz] in world units, each > 0");
    }
    return r.diagnostics().size() == before;
}

void parsePair(Reader& r, const toml::table& t, const std::string& path,
               std::vector<FeaturePairSpec>& pairs)
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
            ok = parseElement(r, *n, path + "." + side, pair.type, element) && ok;
        } else {
            r.missing(t, path + "." + side, "a table with origin, axes and scale");
            ok = false;
        }
    }
    if (ok) pairs.push_back(pair);
}

} // namespace

void parsePairs(Reader& r, const toml::node& node, std::vector<FeaturePairSpec>& pairs)
{
    r.eachTable(node, "pair", [&](const toml::table& t, const std::string& path) {
        parsePair(r, t, path, pairs);
    });
}

} // namespace volmorph::detail
