// The scene `volmorph edit` works on: its text (SceneDocument: every byte an edit does not touch
// stays as written), the edits the page asks for as JSON, undo and redo, and what the validator
// says about the result, each error placed at the pair and the side it concerns.
//
// The page edits feature pairs (a value of a pair, `pair[2].target.origin`, a new pair, a copy of
// one, a deletion, the suggested pairs) and the timing's sweep it drags (`timing.sweep.origin`).
// Every edit is one step of undo. An edit that leaves
// the scene invalid (a scale of 0 typed in) is kept, with its errors, as a text editor keeps a
// typo: the last valid scene stays what the in-between is made from until the errors are fixed
// or undone. Saving an invalid scene is refused.
#pragma once

#include <volmorph/Scene.h>
#include <volmorph/SceneDocument.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace volmorph::editor {

/// A request that is malformed or names what does not exist: answered 400 with the message.
struct BadRequest : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A well-formed request the state refuses (saving an invalid scene, a file changed on disk since
/// it was read): answered 409 with the message.
struct Conflict : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// One validator error, placed: `pair` from 1 (0: not inside a pair), `side` "source", "target"
/// or empty (the pair as a whole, or not in a pair).
struct PlacedError {
    std::string where; ///< file:line:col
    std::string message;
    int pair = 0;
    std::string side;
};

class EditDocument {
public:
    /// Reads and validates the scene; throws UserError (file:line:col) when it is not a valid
    /// scene: the editor starts from one.
    explicit EditDocument(std::filesystem::path scene);

    /// Applies one edit, `action` with its JSON `body`:
    ///  - "set"       {"key": "pair[2].target.origin", "value": [x, y, z]}; keys pair[N].type,
    ///                pair[N].source|target.origin|axes|scale; values as the scene writes them
    ///                (axes [[x], [y]]; scale a number or three); timing.spread and
    ///                timing.sweep.origin|direction|length where the file has them; or
    ///                {"values": {key: value, ...}}: several keys in one step;
    ///  - "add"       {"type": "point", "source": {"origin": [...], "axes": ..., "scale": ...},
    ///                "target": {...}} (axes and scale optional);
    ///  - "duplicate" {"index": N}: a copy of pair N appended;
    ///  - "delete"    {"index": N};
    ///  - "undo", "redo" {}.
    /// Throws BadRequest (nothing changed) for a malformed body, an unknown action or key, a pair
    /// that does not exist, or a value that is not TOML's; Conflict to duplicate while the scene is
    /// invalid.
    void apply(const std::string& action, const nlohmann::json& body);

    /// Appends `pairs` (one step of undo), each after the comment `comment`.
    void appendPairs(const std::vector<FeaturePairSpec>& pairs, const std::string& comment);

    /// Writes the text to the scene file atomically. Conflict when the scene is invalid, or when
    /// the file no longer holds what was read or last saved (another program changed it).
    void save();

    /// The last valid scene: the current text's when valid() is true.
    const Scene& scene() const { return mScene; }
    bool valid() const { return mErrors.empty(); }
    const std::vector<PlacedError>& errors() const { return mErrors; }
    const std::string& text() const { return mDocument.text(); }
    /// The file's text as read or last saved.
    const std::string& savedText() const { return mSaved; }
    /// Counts the changes to the last valid scene's pairs, and to its timing (spread and sweep):
    /// what the in-between depends on.
    uint64_t pairsVersion() const { return mPairsVersion; }
    uint64_t timingVersion() const { return mTimingVersion; }

    /// {"scene", "dirty", "canUndo", "canRedo", "valid", "pairs": [...], "errors": [...],
    /// "camera": {...}, "landmarks", "timing"}: what the page draws; "landmarks" is true in surface
    /// mode (the pairs are landmarks: points only, no suggestions); "timing": {"spread", "sweep":
    /// {"origin", "direction", "length"} or null, "regions": how many}.
    nlohmann::json state() const;

private:
    /// Makes `next` the text (one step of undo): re-validates, places the errors.
    void commit(SceneDocument next);
    void revalidate();
    void set(const nlohmann::json& body, SceneDocument& next) const;

    std::filesystem::path mPath;
    SceneDocument mDocument;
    std::string mSaved; ///< the file's text as read or last saved
    Scene mScene;
    std::vector<PlacedError> mErrors;
    std::vector<std::string> mUndo, mRedo; ///< texts
    uint64_t mPairsVersion = 0, mTimingVersion = 0;
};

/// A feature element from the page's JSON ({"origin", "axes"?, "scale"?}); BadRequest when it is
/// not one (the validator checks the values themselves once written).
FeatureElement elementFromJson(const nlohmann::json& json);
nlohmann::json elementToJson(const FeatureElement& element);

} // namespace volmorph::editor
