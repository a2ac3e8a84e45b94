// [warp] (weights, tolerance), [blend] (mode, schedules, dust), [variational] and [surface].
#include "TableParsers.h"

#include <cmath>
#include <cstdlib>
#include <limits>

namespace volmorph::detail {
namespace {

const std::vector<std::string> kWarpKeys = {"epsilon", "tolerance", "weighting", "a", "b", "p"};
const std::vector<std::string> kBlendKeys = {"mode", "density",    "color",
                                             "sdf",  "min_island", "grids"};
const std::vector<std::string> kSurfaceKeys = {"correspondence", "interpolation", "kernel"};
const std::vector<std::string> kVariationalKeys = {"constraints", "normal_offset", "time_scale",
                                                   "influence"};

void parseSchedule(Reader& r, const toml::node& node, const std::string& path, ScheduleSpec& s)
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
                r.error(r.at(node), path + ": sigmoid(k) needs a steepness 0 < k <= 1000, got \"" +
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
        r.error(r.at(node), path +
                                ": expected a schedule name or an array of [t, tau] points, got " +
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
        const auto tau = r.numberIn(*pt->get(1), ppath + " tau", 0.0, true, 1.0, "tau from 0 to 1");
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
        r.error(r.at(node), path + ": a curve needs at least two points, starting at [0, 0] and "
                                   "ending at [1, 1]");
        return;
    }
    s.kind = ScheduleSpec::Kind::Curve;
    s.points = std::move(points);
}

/// blend.grids: a schedule per named grid.
void parseGridSchedules(Reader& r, const toml::node& node, BlendSpec& b)
{
    const toml::table* t = r.table(node, "blend.grids");
    if (!t) return;
    for (auto&& [key, value] : *t) {
        const std::string name(key.str());
        if (name == "density" || name == "sdf" || name == "Cd") {
            r.error(r.at(key.source()), "blend.grids." + name + ": the " + name +
                                            " grid follows blend." +
                                            (name == "Cd" ? "color" : name) +
                                            "; blend.grids names the other grids a volume carries");
            continue;
        }
        BlendSpec::GridSchedule& g = b.grids[name];
        g.where = r.at(key.source());
        parseSchedule(r, value, "blend.grids." + name, g.schedule);
    }
}

} // namespace

void parseWarp(Reader& r, const toml::node& node, WarpSpec& w)
{
    const toml::table* t = r.table(node, "warp");
    if (!t) return;
    r.checkKeys(*t, "warp", kWarpKeys);

    const double big = std::numeric_limits<double>::max();
    if (const toml::node* n = t->get("epsilon"))
        if (auto v = r.numberIn(*n, "warp.epsilon", 0.0, true, big, "a length >= 0 in world units"))
            w.epsilon = *v;
    if (const toml::node* n = t->get("tolerance"))
        if (auto v = r.numberIn(*n, "warp.tolerance", 0.0, true, 64.0,
                                "a tolerance from 0 (exact) to 64 voxels"))
            w.toleranceVoxels = *v;
    if (const toml::node* n = t->get("weighting"))
        if (auto s = r.choice(*n, "warp.weighting", {"inverse-square", "beier-neely"}))
            w.weighting = *s == "beier-neely" ? Weighting::BeierNeely : Weighting::InverseSquare;
    if (const toml::node* n = t->get("a"))
        if (auto v = r.numberIn(*n, "warp.a", 0.0, false, big, "a length > 0 in world units"))
            w.a = *v;
    if (const toml::node* n = t->get("b"))
        if (auto v = r.numberIn(*n, "warp.b", 0.0, true, 16.0, "an exponent from 0 to 16"))
            w.b = *v;
    if (const toml::node* n = t->get("p"))
        if (auto v = r.numberIn(*n, "warp.p", 0.0, true, 1.0, "an exponent from 0 to 1")) w.p = *v;
    if (w.weighting == Weighting::InverseSquare)
        for (const char* k : {"a", "b", "p"})
            if (const toml::node* n = t->get(k))
                r.error(r.at(*n),
                        std::string("warp.") + k + ": only used with weighting = \"beier-neely\"");
}

void parseBlend(Reader& r, const toml::node& node, BlendSpec& b)
{
    const toml::table* t = r.table(node, "blend");
    if (!t) return;
    r.checkKeys(*t, "blend", kBlendKeys);

    if (const toml::node* n = t->get("mode"))
        if (auto s = r.choice(*n, "blend.mode", {"density", "sdf", "variational", "surface"}))
            b.mode = *s == "sdf"           ? BlendMode::Sdf
                     : *s == "variational" ? BlendMode::Variational
                     : *s == "surface"     ? BlendMode::Surface
                                           : BlendMode::Density;
    if (const toml::node* n = t->get("density")) parseSchedule(r, *n, "blend.density", b.density);
    if (const toml::node* n = t->get("color")) parseSchedule(r, *n, "blend.color", b.color);
    if (const toml::node* n = t->get("sdf")) parseSchedule(r, *n, "blend.sdf", b.sdf);
    if (const toml::node* n = t->get("min_island"))
        if (auto v = r.integerIn(*n, "blend.min_island", 0, 1000000000))
            b.minIslandVoxels = int(*v);
    if (const toml::node* n = t->get("grids")) parseGridSchedules(r, *n, b);
}

void parseVariational(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                      VariationalSpec& v, std::vector<InfluenceSpec>& influences)
{
    const toml::table* t = r.table(node, "variational");
    if (!t) return;
    r.checkKeys(*t, "variational", kVariationalKeys);
    v.where = r.at(node);
    if (const toml::node* n = t->get("constraints"))
        if (auto c = r.integerIn(*n, "variational.constraints", 100, 1000000))
            v.constraints = int(*c);
    if (const toml::node* n = t->get("normal_offset"))
        if (auto d = r.numberIn(*n, "variational.normal_offset", 0.0, false, 16.0,
                                "a depth in voxels, 0 < depth <= 16"))
            v.normalOffsetVoxels = *d;
    if (const toml::node* n = t->get("time_scale"))
        if (auto s = r.numberIn(*n, "variational.time_scale", 0.0, false,
                                std::numeric_limits<double>::max(),
                                "a positive length in world units per unit of t"))
            v.timeScale = *s;
    if (const toml::node* n = t->get("influence"))
        r.eachTable(
            *n, "variational.influence", [&](const toml::table& shape, const std::string& path) {
                InfluenceSpec influence;
                parseObject(r, shape, path, folder, influence.object, {"t"});
                if (influence.object.isSequence())
                    r.error(r.at(*shape.get("volume")),
                            path + ".volume: an influence shape is one volume, not a sequence");
                if (const toml::node* time = shape.get("t")) {
                    if (auto at = r.numberIn(*time, path + ".t", 0.0, false, 1.0,
                                             "a time strictly between 0 and 1")) {
                        if (*at >= 1.0)
                            r.error(r.at(*time), path +
                                                     ".t: expected a time strictly between 0 and "
                                                     "1 (the sides are at 0 and 1), got 1");
                        influence.t = *at;
                    }
                } else {
                    r.missing(shape, path + ".t", "the time the shape is placed at, 0 < t < 1");
                }
                influences.push_back(std::move(influence));
            });
}

void parseSurface(Reader& r, const toml::node& node, SurfaceSpec& s)
{
    const toml::table* t = r.table(node, "surface");
    if (!t) return;
    r.checkKeys(*t, "surface", kSurfaceKeys);
    s.where = r.at(node);
    if (const toml::node* n = t->get("correspondence")) {
        s.correspondenceWhere = r.at(*n);
        if (auto c = r.choice(*n, "surface.correspondence",
                              {"auto", "identity", "star", "sphere", "disk"})) {
            s.correspondence = *c == "identity" ? Correspondence::Identity
                               : *c == "star"   ? Correspondence::Star
                               : *c == "sphere" ? Correspondence::Sphere
                               : *c == "disk"   ? Correspondence::Disk
                                                : Correspondence::Auto;
        }
    }
    if (const toml::node* n = t->get("interpolation"))
        if (auto i = r.choice(*n, "surface.interpolation", {"arap", "linear"}))
            s.interpolation =
                *i == "linear" ? SurfaceInterpolation::Linear : SurfaceInterpolation::Arap;
    if (const toml::node* n = t->get("kernel")) {
        const toml::table* k = r.table(*n, "surface.kernel");
        if (!k) return;
        r.checkKeys(*k, "surface.kernel", {"source", "target"});
        std::optional<Vec3d> a, b;
        if (const toml::node* p = k->get("source"))
            a = r.vec3(*p, "surface.kernel.source");
        else
            r.missing(*k, "surface.kernel.source", "a point inside the source, [x, y, z]");
        if (const toml::node* p = k->get("target"))
            b = r.vec3(*p, "surface.kernel.target");
        else
            r.missing(*k, "surface.kernel.target", "a point inside the target, [x, y, z]");
        if (a && b) s.kernel = std::pair{*a, *b};
        if (s.correspondence != Correspondence::Star)
            r.error(r.at(*n), "surface.kernel: only used with correspondence = \"star\"");
    }
}

} // namespace volmorph::detail
