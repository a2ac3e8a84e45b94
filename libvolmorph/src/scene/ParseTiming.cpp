// [timing]: spread, sweep and [[timing.region]] (TimingSettings.h, LocalTime.h).
#include "TableParsers.h"

#include <limits>

namespace volmorph::detail {
namespace {

const std::vector<std::string> kTimingKeys = {"spread", "sweep", "region"};
const std::vector<std::string> kSweepKeys = {"origin", "direction", "length"};

std::optional<TimingSweep> parseSweep(Reader& r, const toml::node& node)
{
    const toml::table* t = r.table(node, "timing.sweep");
    if (!t) return std::nullopt;
    r.checkKeys(*t, "timing.sweep", kSweepKeys);
    TimingSweep sweep;
    sweep.where = r.at(node);
    bool ok = true;
    if (const toml::node* n = t->get("origin")) {
        const auto v = r.vec3(*n, "timing.sweep.origin");
        ok = ok && v;
        if (v) sweep.origin = *v;
    }
    if (const toml::node* n = t->get("direction")) {
        const auto v = r.direction(*n, "timing.sweep.direction");
        ok = ok && v;
        if (v) sweep.direction = *v;
    } else {
        r.missing(node, "timing.sweep.direction", "the way the delay grows, [x, y, z]");
        ok = false;
    }
    if (const toml::node* n = t->get("length")) {
        const auto v =
            r.numberIn(*n, "timing.sweep.length", 0.0, false, std::numeric_limits<double>::max(),
                       "a positive length in world units");
        ok = ok && v;
        if (v) sweep.length = *v;
    } else {
        r.missing(node, "timing.sweep.length",
                  "world units along the direction over which the delay grows to the spread");
        ok = false;
    }
    return ok ? std::optional<TimingSweep>(sweep) : std::nullopt;
}

void parseRegion(Reader& r, const toml::table& table, const std::string& path,
                 const std::filesystem::path& folder, double spread,
                 std::vector<TimingRegionSpec>& regions)
{
    TimingRegionSpec region;
    region.where = r.at(table);
    parseObject(r, table, path, folder, region.shape, {"start", "softness"});
    if (region.shape.isSequence())
        r.error(r.at(*table.get("volume")),
                path + ".volume: a region is one volume, not a sequence");
    if (const toml::node* n = table.get("start")) {
        if (auto v =
                r.numberIn(*n, path + ".start", 0.0, true, spread,
                           "a delay in t from 0 to timing.spread (" + formatNumber(spread) + ")"))
            region.start = *v;
    } else {
        r.missing(table, path + ".start", "its delay, in t, from 0 to timing.spread");
    }
    if (const toml::node* n = table.get("softness"))
        if (auto v = r.numberIn(*n, path + ".softness", 0.0, true,
                                std::numeric_limits<double>::max(), "a length >= 0 in world units"))
            region.softness = *v;
    regions.push_back(std::move(region));
}

} // namespace

void parseTiming(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                 TimingSettings& timing, std::vector<TimingRegionSpec>& regions)
{
    const toml::table* t = r.table(node, "timing");
    if (!t) return;
    r.checkKeys(*t, "timing", kTimingKeys);
    timing.where = r.at(node);
    if (const toml::node* n = t->get("spread")) {
        if (auto v = r.number(*n, "timing.spread")) {
            if (*v >= 0.0 && *v < 1.0)
                timing.spread = *v;
            else
                r.error(r.at(*n),
                        "timing.spread: expected a fraction of the morph, 0 <= spread < 1, got " +
                            formatNumber(*v));
        }
    } else {
        r.missing(
            node, "timing.spread",
            "how much later the last place starts than the first, a fraction 0 <= spread < 1");
    }
    if (const toml::node* n = t->get("sweep")) timing.sweep = parseSweep(r, *n);
    if (const toml::node* n = t->get("region"))
        r.eachTable(*n, "timing.region", [&](const toml::table& region, const std::string& path) {
            parseRegion(r, region, path, folder, timing.spread, regions);
        });
    if (timing.spread > 0.0 && !t->get("sweep") && !t->get("region"))
        r.error(timing.where, "[timing]: a spread needs a sweep or a [[timing.region]] to say "
                              "where the morph starts late");
}

} // namespace volmorph::detail
