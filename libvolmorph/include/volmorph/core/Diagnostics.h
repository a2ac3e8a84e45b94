// Diagnostics for errors a user can cause (scene files, meshes, flags, files).
//
// A user error is reported as one line per problem, `FILE:LINE:COL: message`, in the form compilers
// use so editors and farm logs can jump to it; the program then exits non-zero. Internal bugs are
// assertions, never Diagnostics.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace volmorph {

/// A place in a user's file. line and column are 1-based; 0 means "unknown" (the whole file).
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;

    /// "file:line:col", "file:line" or "file", whichever is known.
    std::string str() const;
};

struct Diagnostic {
    SourceLocation where;
    std::string message;
    /// The user's file the problem is that it does not exist (a scene's mesh or volume), when it
    /// is: front ends that report a missing file as such (Python's FileNotFoundError) read it.
    std::string missingFile{};

    /// "file:line:col: message"
    std::string str() const;
};

/// Thrown for errors the user can fix. Carries every problem found, not only the first, so that a
/// scene with three typos is fixed in one edit.
class UserError : public std::runtime_error {
public:
    explicit UserError(std::vector<Diagnostic> diagnostics);
    UserError(SourceLocation where, std::string message);

    const std::vector<Diagnostic>& diagnostics() const { return mDiagnostics; }

private:
    std::vector<Diagnostic> mDiagnostics;
};

/// Collects diagnostics while a parser or validator keeps going after the first problem.
class DiagnosticList {
public:
    void error(SourceLocation where, std::string message, std::string missingFile = {});
    bool empty() const { return mItems.empty(); }
    size_t size() const { return mItems.size(); }
    const std::vector<Diagnostic>& items() const { return mItems; }
    /// Throws UserError with everything collected, if anything was.
    void throwIfAny() const;

private:
    std::vector<Diagnostic> mItems;
};

/// Levenshtein distance, for "did you mean" suggestions.
size_t editDistance(const std::string& a, const std::string& b);

/// The candidate closest to `word` when it is a plausible typo of it (small edit distance
/// relative to the length), else an empty string.
std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates);

} // namespace volmorph
