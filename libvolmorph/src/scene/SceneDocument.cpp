#include <volmorph/SceneDocument.h>

#include <volmorph/Scene.h>

#include <volmorph/core/AtomicFile.h>
#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/FileText.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace volmorph {
namespace {

toml::table parseText(const std::string& text, const std::filesystem::path& path)
{
    try {
        return toml::parse(text, path.string());
    } catch (const toml::parse_error& e) {
        const toml::source_position p = e.source().begin;
        throw UserError(SourceLocation{path.string(), int(p.line), int(p.column)},
                        "TOML syntax error: " + std::string(e.description()));
    }
}

/// The byte offset of the start of line `line` (from 1); the text's size past its last line.
size_t lineStart(const std::string& text, uint32_t line)
{
    size_t offset = 0;
    for (uint32_t l = 1; l < line; ++l) {
        offset = text.find('\n', offset);
        if (offset == std::string::npos) return text.size();
        ++offset;
    }
    return offset;
}

/// The byte offset of a toml++ position (line and column from 1; columns count code points).
size_t offsetOf(const std::string& text, const toml::source_position& p)
{
    size_t offset = lineStart(text, p.line);
    for (uint32_t c = 1; c < p.column && offset < text.size(); ++c) {
        ++offset;
        while (offset < text.size() && (static_cast<unsigned char>(text[offset]) & 0xC0) == 0x80)
            ++offset;
    }
    return offset;
}

/// True for a table opened by a [header] line (not inline, not made by dotted keys).
bool isHeaderTable(const std::string& text, const toml::node& node)
{
    const toml::table* t = node.as_table();
    if (!t || t->is_inline()) return false;
    const size_t at = offsetOf(text, node.source().begin);
    return at < text.size() && text[at] == '[';
}

/// The last line of `node` and of everything in it.
uint32_t lastLine(const toml::node& node)
{
    uint32_t line = node.source().end.line;
    if (const toml::table* t = node.as_table())
        for (const auto& entry : *t) line = std::max(line, lastLine(entry.second));
    if (const toml::array* a = node.as_array())
        for (const toml::node& v : *a) line = std::max(line, lastLine(v));
    return line;
}

/// The last line of a header table's own keys (its header's when it has none): before its
/// sub-tables' headers.
uint32_t lastOwnLine(const std::string& text, const toml::table& table)
{
    uint32_t line = table.source().begin.line;
    for (const auto& entry : table)
        if (!isHeaderTable(text, entry.second)) line = std::max(line, lastLine(entry.second));
    return line;
}

struct KeyStep {
    std::string name;
    int index = 0; ///< from 1 into an array of tables; 0: none
};

std::vector<KeyStep> splitKey(const std::string& key)
{
    std::vector<KeyStep> steps;
    std::istringstream in(key);
    for (std::string part; std::getline(in, part, '.');) {
        KeyStep step;
        const size_t bracket = part.find('[');
        step.name = part.substr(0, bracket);
        if (bracket != std::string::npos) step.index = std::atoi(part.c_str() + bracket + 1);
        if (step.name.empty() || (bracket != std::string::npos && step.index < 1))
            throw std::invalid_argument("not a key: \"" + key + "\"");
        steps.push_back(step);
    }
    if (steps.empty()) throw std::invalid_argument("an empty key");
    return steps;
}

/// The table the first `count` steps lead to from `root`, null when there is none.
const toml::table* tableAt(const toml::table& root, const std::vector<KeyStep>& steps, size_t count)
{
    const toml::table* t = &root;
    for (size_t i = 0; i < count && t; ++i) {
        const toml::node* n = t->get(steps[i].name);
        if (n && steps[i].index > 0) {
            const toml::array* a = n->as_array();
            n = a && size_t(steps[i].index) <= a->size() ? a->get(size_t(steps[i].index) - 1)
                                                         : nullptr;
        }
        t = n ? n->as_table() : nullptr;
    }
    return t;
}

/// The file's line ending: "\r\n" where its first line ends so, else "\n".
std::string lineEnding(const std::string& text)
{
    const size_t n = text.find('\n');
    return n != std::string::npos && n > 0 && text[n - 1] == '\r' ? "\r\n" : "\n";
}

const toml::array* pairsOf(const toml::table& root)
{
    const toml::node* n = root.get("pair");
    return n ? n->as_array() : nullptr;
}

} // namespace

SceneDocument::SceneDocument(std::string text, std::filesystem::path path)
    : mText(std::move(text)), mPath(std::move(path))
{
    parseText(mText, mPath);
}

SceneDocument SceneDocument::read(const std::filesystem::path& path)
{
    std::optional<std::string> text = readFileText(path);
    if (!text) throw UserError(SourceLocation{path.string()}, "cannot read scene file");
    return SceneDocument(std::move(*text), path);
}

void SceneDocument::set(const std::string& key, const std::string& value)
{
    const toml::table root = parseText(mText, mPath);
    const std::vector<KeyStep> steps = splitKey(key);
    const toml::table* parent = tableAt(root, steps, steps.size() - 1);
    if (!parent || steps.back().index > 0)
        throw std::invalid_argument("\"" + key + "\" names no value in a table of the file");
    const std::string& name = steps.back().name;
    std::string next = mText;
    if (const toml::node* old = parent->get(name)) {
        const size_t a = offsetOf(mText, old->source().begin);
        const size_t b = offsetOf(mText, old->source().end);
        next.replace(a, b - a, value);
    } else if (parent->is_inline()) {
        size_t at = offsetOf(mText, parent->source().end) - 1; // the closing brace
        while (at > 0 && std::isspace(static_cast<unsigned char>(mText[at - 1]))) --at;
        const bool empty = at > 0 && mText[at - 1] == '{';
        next.insert(at, (empty ? " " : ", ") + name + " = " + value + (empty ? " " : ""));
    } else if (parent != &root && isHeaderTable(mText, *parent)) {
        const size_t at = lineStart(mText, lastOwnLine(mText, *parent) + 1);
        const std::string eol = lineEnding(mText);
        const std::string before = at > 0 && mText[at - 1] != '\n' ? eol : "";
        next.insert(at, before + name + " = " + value + eol);
    } else {
        throw std::invalid_argument("\"" + key + "\": a new key goes in a [table] or an inline " +
                                    "table; add this one by hand");
    }
    try {
        parseText(next, mPath);
    } catch (const UserError& e) {
        throw std::invalid_argument("\"" + key + "\" = " + value + ": " + e.what());
    }
    mText = std::move(next);
}

void SceneDocument::appendPair(const std::vector<std::string>& lines,
                               const std::vector<std::string>& comment)
{
    const toml::table root = parseText(mText, mPath);
    const toml::array* pairs = pairsOf(root);
    const size_t at =
        pairs && !pairs->empty() ? lineStart(mText, lastLine(pairs->back()) + 1) : mText.size();
    const std::string eol = lineEnding(mText);
    std::string block = at > 0 && mText[at - 1] != '\n' ? eol + eol : eol;
    for (const std::string& c : comment) block += "# " + c + eol;
    block += "[[pair]]" + eol;
    for (const std::string& line : lines) block += line + eol;
    std::string next = mText;
    next.insert(at, block);
    try {
        parseText(next, mPath);
    } catch (const UserError& e) {
        throw std::invalid_argument(std::string("the new pair: ") + e.what());
    }
    mText = std::move(next);
}

void SceneDocument::removePair(int index)
{
    const toml::table root = parseText(mText, mPath);
    const toml::array* pairs = pairsOf(root);
    if (!pairs || index < 1 || size_t(index) > pairs->size())
        throw std::invalid_argument("no [[pair]] number " + std::to_string(index));
    const toml::node& pair = *pairs->get(size_t(index) - 1);
    uint32_t first = pair.source().begin.line;
    auto isComment = [&](uint32_t line) {
        const size_t a = lineStart(mText, line);
        const size_t b = mText.find_first_not_of(" \t", a);
        return b != std::string::npos && mText[b] == '#';
    };
    while (first > 1 && isComment(first - 1)) --first;
    size_t a = lineStart(mText, first);
    const size_t b = lineStart(mText, lastLine(pair) + 1);
    // The blank line that separated the pair from what came before goes with it when another
    // blank line (or the end) follows.
    const std::string eol = lineEnding(mText);
    const size_t k = eol.size();
    const bool blankBefore = a >= 2 * k && mText.compare(a - 2 * k, 2 * k, eol + eol) == 0;
    if (blankBefore && (b >= mText.size() || mText.compare(b, k, eol) == 0)) a -= k;
    mText.erase(a, b - a);
}

int SceneDocument::pairCount() const
{
    const toml::table root = parseText(mText, mPath);
    const toml::array* pairs = pairsOf(root);
    return pairs ? int(pairs->size()) : 0;
}

std::vector<SceneDocument::PairLines> SceneDocument::pairLines() const
{
    const toml::table root = parseText(mText, mPath);
    std::vector<PairLines> lines;
    const toml::array* pairs = pairsOf(root);
    if (!pairs) return lines;
    for (const toml::node& node : *pairs) {
        PairLines p;
        p.header = int(node.source().begin.line);
        p.last = int(lastLine(node));
        if (const toml::table* t = node.as_table()) {
            if (const toml::node* n = t->get("source"))
                p.sourceFirst = int(n->source().begin.line), p.sourceLast = int(lastLine(*n));
            if (const toml::node* n = t->get("target"))
                p.targetFirst = int(n->source().begin.line), p.targetLast = int(lastLine(*n));
        }
        lines.push_back(p);
    }
    return lines;
}

void SceneDocument::save(const std::filesystem::path& path) const
{
    writeAtomically(path, [this](const std::filesystem::path& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << mText;
        out.close();
        if (!out) throw std::runtime_error("cannot write " + temporary.string());
    });
}

std::string tomlNumber(double value)
{
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    std::string text(buffer, result.ptr);
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0"; // "n": inf, nan
    return text;
}

std::string tomlArray(const std::vector<double>& values)
{
    std::string text = "[";
    for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + tomlNumber(values[i]);
    return text + "]";
}

std::string tomlRounded(double value)
{
    // Past 2^53 / 1e4 a fourth decimal is not held, and "%.4f" would write every digit of the
    // integer part (a hundred for 1e92, more than a TOML reader takes): the exact shortest form.
    if (!(std::abs(value) < 1e11)) return tomlNumber(value);
    char text[64];
    std::snprintf(text, sizeof text, "%.4f", std::round(value * 1e4) / 1e4 + 0.0);
    std::string s(text);
    while (s.size() > 1 && s.back() == '0' && s[s.size() - 2] != '.') s.pop_back();
    return s == "-0.0" ? "0.0" : s;
}

namespace {

std::string roundedVec(const Vec3d& v)
{
    return "[" + tomlRounded(v.x()) + ", " + tomlRounded(v.y()) + ", " + tomlRounded(v.z()) + "]";
}

std::string elementTable(const FeatureElement& e, FeatureType type)
{
    const FeatureElement identity;
    const bool bare = type == FeatureType::Point && e.xAxis == identity.xAxis &&
                      e.yAxis == identity.yAxis && e.scale == identity.scale;
    if (bare) return "{ origin = " + roundedVec(e.origin) + " }";
    return "{ origin = " + roundedVec(e.origin) + ", axes = [" + roundedVec(e.xAxis) + ", " +
           roundedVec(e.yAxis) + "], scale = " + roundedVec(e.scale) + " }";
}

} // namespace

std::vector<std::string> pairTableLines(const FeaturePairSpec& pair)
{
    return {std::string("type = \"") + toString(pair.type) + "\"",
            "source = " + elementTable(pair.source, pair.type),
            "target = " + elementTable(pair.target, pair.type)};
}

} // namespace volmorph
