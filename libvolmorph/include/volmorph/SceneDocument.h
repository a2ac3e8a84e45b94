// A scene file's text, edited as its author would edit it: a value is replaced where it is written,
// a key a table lacks is added inside it, a new [[pair]] table goes after the last one, a pair is
// removed with the comment lines directly above it. Every other byte stays as it was: comments,
// layout, the spelling of numbers. The feature-pair editor (issue 39) and `pairs suggest -o` write
// scene files through it; saves are atomic.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace volmorph {

struct FeaturePairSpec;

class SceneDocument {
public:
    /// Reads `path`; throws UserError (file:line:col) when it is not TOML.
    static SceneDocument read(const std::filesystem::path& path);

    /// From text; `path` names it in errors. Throws UserError when it is not TOML.
    explicit SceneDocument(std::string text, std::filesystem::path path = "scene.toml");

    const std::string& text() const { return mText; }

    /// Sets the value at `key` to `value` (TOML text: "[0.1, 0.2, 0.3]", "\"box\"", "0.5"),
    /// written where the old one is; a key its table lacks is added to it (before an inline
    /// table's closing brace, or as a line after a table's last key). `key`: dotted names, with
    /// 1-based indices into arrays of tables: "pair[2].target.origin", "warp.epsilon". Throws
    /// std::invalid_argument when `key` names no table, or when the result would not be TOML (the
    /// text is then unchanged).
    void set(const std::string& key, const std::string& value);

    /// Appends a [[pair]] table of `lines` ("key = value" each) after the last pair's last line
    /// (at the end of the file when there is none), after a blank line and the `comment` lines
    /// (each written "# ..."). Throws std::invalid_argument when the result would not be TOML.
    void appendPair(const std::vector<std::string>& lines,
                    const std::vector<std::string>& comment = {});

    /// Removes [[pair]] number `index` (from 1): its header, its keys and sub-tables, and the
    /// comment lines directly above its header. Throws std::invalid_argument for no such pair.
    void removePair(int index);

    /// The number of [[pair]] tables.
    int pairCount() const;

    /// Where a [[pair]] is written, in lines from 1: its header to its last line, and the lines
    /// its `source` and `target` values span (0, 0 when absent). For placing a validator's error
    /// at the element it concerns.
    struct PairLines {
        int header = 0, last = 0;
        int sourceFirst = 0, sourceLast = 0, targetFirst = 0, targetLast = 0;
    };
    /// Every [[pair]]'s lines, in order.
    std::vector<PairLines> pairLines() const;

    /// Writes the text to `path` atomically: the file is replaced whole or not at all.
    void save(const std::filesystem::path& path) const;

private:
    std::string mText;
    std::filesystem::path mPath;
};

/// A number as a scene file writes it: the shortest text that reads back to the same double, with a
/// decimal point ("0.5", "3.0", "1e-07").
std::string tomlNumber(double value);

/// "[a, b, c]" of tomlNumber's.
std::string tomlArray(const std::vector<double>& values);

/// A number to 1e-4 (a tenth of a millimetre at metre scale), as TOML: "0.25", "-0.0012", "3.0".
std::string tomlRounded(double value);

/// A [[pair]] table's lines as the scenes write theirs: `type = "box"`, then `source = { origin =
/// [...], axes = [[...], [...]], scale = [...] }` and `target = ...`, numbers to 1e-4
/// (tomlRounded). A point whose frame is the identity and whose scale is 1 writes its origin alone.
std::vector<std::string> pairTableLines(const FeaturePairSpec& pair);

} // namespace volmorph
