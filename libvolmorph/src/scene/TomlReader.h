// Typed reading of a toml++ tree with positions: every problem is collected as FILE:LINE:COL with
// what was expected, and reading goes on. Private to the scene stage.
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/Scene.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace volmorph::detail {

inline const char* typeName(const toml::node& n)
{
    using T = toml::node_type;
    static constexpr std::pair<T, const char*> kNames[] = {{T::table, "a table"},
                                                           {T::array, "an array"},
                                                           {T::string, "a string"},
                                                           {T::integer, "an integer"},
                                                           {T::floating_point, "a number"},
                                                           {T::boolean, "a boolean"},
                                                           {T::date, "a date"},
                                                           {T::time, "a time"},
                                                           {T::date_time, "a date-time"}};
    for (const auto& [type, name] : kNames)
        if (n.type() == type) return name;
    return "nothing";
}

inline std::string formatNumber(double v)
{
    std::ostringstream s;
    s << v;
    return s.str();
}

/// Reads typed values out of the toml++ tree, reporting every problem with its position.
/// Each reader returns std::nullopt after reporting; callers then keep the default and go on.
class Reader {
public:
    explicit Reader(std::string file) : mFile(std::move(file)) {}

    DiagnosticList& diagnostics() { return mDiagnostics; }

    SourceLocation at(const toml::source_region& r) const
    {
        return SourceLocation{mFile, int(r.begin.line), int(r.begin.column)};
    }
    SourceLocation at(const toml::node& n) const { return at(n.source()); }

    void error(const SourceLocation& where, std::string message, std::string missingFile = {})
    {
        mDiagnostics.error(where, std::move(message), std::move(missingFile));
    }

    /// Reports keys of `table` that are not in `allowed`. `path` names the table ("render.camera").
    void checkKeys(const toml::table& table, const std::string& path,
                   const std::vector<std::string>& allowed)
    {
        for (auto&& [key, node] : table) {
            const std::string name(key.str());
            if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
            std::string message =
                "unknown key '" + name + "'" +
                (path.empty() ? std::string(" at the top level") : " in [" + path + "]");
            const std::string suggestion = closestMatch(name, allowed);
            if (!suggestion.empty())
                message += "; did you mean '" + suggestion + "'?";
            else
                message += "; expected one of: " + joinKeys(allowed);
            error(at(key.source()), message);
        }
    }

    const toml::table* table(const toml::node& n, const std::string& path)
    {
        if (const toml::table* t = n.as_table()) return t;
        error(at(n), path + ": expected a table, got " + typeName(n));
        return nullptr;
    }

    std::optional<double> number(const toml::node& n, const std::string& path)
    {
        std::optional<double> v;
        if (const auto* i = n.as_integer())
            v = double(i->get());
        else if (const auto* f = n.as_floating_point())
            v = f->get();
        else {
            error(at(n), path + ": expected a number, got " + typeName(n));
            return std::nullopt;
        }
        if (!std::isfinite(*v)) {
            error(at(n), path + ": expected a finite number, got " + formatNumber(*v));
            return std::nullopt;
        }
        return v;
    }

    /// A number with lo < v (or lo <= v when loInclusive) and v <= hi. `unit` ends the message.
    std::optional<double> numberIn(const toml::node& n, const std::string& path, double lo,
                                   bool loInclusive, double hi, const std::string& what)
    {
        const std::optional<double> v = number(n, path);
        if (!v) return std::nullopt;
        const bool aboveLo = loInclusive ? *v >= lo : *v > lo;
        if (!aboveLo || *v > hi) {
            error(at(n), path + ": expected " + what + ", got " + formatNumber(*v));
            return std::nullopt;
        }
        return v;
    }

    std::optional<int64_t> integerIn(const toml::node& n, const std::string& path, int64_t lo,
                                     int64_t hi)
    {
        const auto* i = n.as_integer();
        if (!i) {
            error(at(n), path + ": expected an integer, got " + typeName(n));
            return std::nullopt;
        }
        if (i->get() < lo || i->get() > hi) {
            error(at(n), path + ": expected an integer from " + std::to_string(lo) + " to " +
                             std::to_string(hi) + ", got " + std::to_string(i->get()));
            return std::nullopt;
        }
        return i->get();
    }

    /// Calls f(table, path) for each table of the array of tables [[name]] at `node`, path being
    /// "name[i]" (from 1).
    template <typename F>
    void eachTable(const toml::node& node, const std::string& name, F&& f)
    {
        const toml::array* tables = node.as_array();
        if (!tables) {
            error(at(node), name + ": expected [[" + name + "]] tables, got " + typeName(node));
            return;
        }
        for (size_t i = 0; i < tables->size(); ++i) {
            const std::string path = name + "[" + std::to_string(i + 1) + "]";
            if (const toml::table* t = table(*tables->get(i), path)) f(*t, path);
        }
    }

    std::optional<bool> boolean(const toml::node& n, const std::string& path)
    {
        if (const auto* b = n.as_boolean()) return b->get();
        error(at(n), path + ": expected true or false, got " + typeName(n));
        return std::nullopt;
    }

    std::optional<std::string> string(const toml::node& n, const std::string& path)
    {
        if (const auto* s = n.as_string()) return s->get();
        error(at(n), path + ": expected a string, got " + typeName(n));
        return std::nullopt;
    }

    /// One of `choices`, with a suggestion for near misses.
    std::optional<std::string> choice(const toml::node& n, const std::string& path,
                                      const std::vector<std::string>& choices)
    {
        const std::optional<std::string> s = string(n, path);
        if (!s) return std::nullopt;
        if (std::find(choices.begin(), choices.end(), *s) != choices.end()) return s;
        std::string message =
            path + ": unknown value \"" + *s + "\"; expected one of: " + joinKeys(choices);
        const std::string suggestion = closestMatch(*s, choices);
        if (!suggestion.empty()) message += " (did you mean \"" + suggestion + "\"?)";
        error(at(n), message);
        return std::nullopt;
    }

    /// An array of exactly three finite numbers.
    std::optional<Vec3d> vec3(const toml::node& n, const std::string& path)
    {
        const toml::array* a = n.as_array();
        if (!a || a->size() != 3) {
            error(at(n), path + ": expected an array of 3 numbers, got " +
                             (a ? "an array of " + std::to_string(a->size()) : typeName(n)));
            return std::nullopt;
        }
        Vec3d v;
        for (int i = 0; i < 3; ++i) {
            const std::optional<double> c =
                number(*a->get(size_t(i)), path + "[" + std::to_string(i) + "]");
            if (!c) return std::nullopt;
            v[i] = *c;
        }
        return v;
    }

    /// [lo, hi]: two finite numbers with lo < hi (or lo <= hi when `strict` is false); `what` says
    /// what they are, for the message.
    std::optional<std::pair<double, double>> interval(const toml::node& n, const std::string& path,
                                                      const std::string& what, bool strict)
    {
        const toml::array* a = n.as_array();
        if (!a || a->size() != 2) {
            error(at(n), path + ": expected [lo, hi], " + what);
            return std::nullopt;
        }
        const auto lo = number(*a->get(0), path + "[0]"), hi = number(*a->get(1), path + "[1]");
        if (!lo || !hi) return std::nullopt;
        if (strict ? !(*lo < *hi) : !(*lo <= *hi)) {
            error(at(n), path + ": expected lo " + (strict ? "<" : "<=") + " hi, got [" +
                             formatNumber(*lo) + ", " + formatNumber(*hi) + "]");
            return std::nullopt;
        }
        return std::pair{*lo, *hi};
    }

    /// A vec3 whose components are all >= 0 (colours).
    std::optional<Vec3d> nonNegativeVec3(const toml::node& n, const std::string& path)
    {
        std::optional<Vec3d> v = vec3(n, path);
        if (v && (v->x() < 0 || v->y() < 0 || v->z() < 0)) {
            error(at(n), path + ": expected components >= 0");
            return std::nullopt;
        }
        return v;
    }

    /// A vec3 whose components are all > 0 (scales).
    std::optional<Vec3d> positiveVec3(const toml::node& n, const std::string& path,
                                      const std::string& unit)
    {
        std::optional<Vec3d> v = vec3(n, path);
        if (v && (v->x() <= 0 || v->y() <= 0 || v->z() <= 0)) {
            error(at(n), path + ": expected every component > 0 (" + unit + "), got [" +
                             formatNumber(v->x()) + ", " + formatNumber(v->y()) + ", " +
                             formatNumber(v->z()) + "]");
            return std::nullopt;
        }
        return v;
    }

    /// A non-zero vec3, returned normalized.
    std::optional<Vec3d> direction(const toml::node& n, const std::string& path)
    {
        std::optional<Vec3d> v = vec3(n, path);
        if (!v) return std::nullopt;
        if (v->length() < 1e-12) {
            error(at(n), path + ": expected a non-zero direction");
            return std::nullopt;
        }
        return v->unit();
    }

    /// Reports a missing required key at its table.
    void missing(const toml::node& table, const std::string& path, const std::string& what)
    {
        error(at(table), "missing " + path + " (" + what + ")");
    }

    /// Reports a missing top-level table; the file is the only sensible place to name.
    void missingTable(const std::string& name, const std::string& what)
    {
        error(SourceLocation{mFile}, "missing [" + name + "] (" + what + ")");
    }

    static std::string joinKeys(const std::vector<std::string>& keys)
    {
        std::string s;
        for (const std::string& k : keys) s += (s.empty() ? "" : ", ") + k;
        return s;
    }

private:
    std::string mFile;
    DiagnosticList mDiagnostics;
};

} // namespace volmorph::detail
