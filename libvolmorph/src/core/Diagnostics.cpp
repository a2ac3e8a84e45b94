#include <volmorph/core/Diagnostics.h>

#include <algorithm>
#include <numeric>

namespace volmorph {

std::string SourceLocation::str() const
{
    std::string s = file.empty() ? std::string("<input>") : file;
    if (line > 0) {
        s += ":" + std::to_string(line);
        if (column > 0) s += ":" + std::to_string(column);
    }
    return s;
}

std::string Diagnostic::str() const
{
    return where.str() + ": " + message;
}

namespace {
std::string joined(const std::vector<Diagnostic>& diagnostics)
{
    std::string s;
    for (const Diagnostic& d : diagnostics) {
        if (!s.empty()) s += '\n';
        s += d.str();
    }
    return s;
}
} // namespace

UserError::UserError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(joined(diagnostics)), mDiagnostics(std::move(diagnostics))
{
}

UserError::UserError(SourceLocation where, std::string message)
    : UserError(std::vector<Diagnostic>{Diagnostic{std::move(where), std::move(message)}})
{
}

void DiagnosticList::error(SourceLocation where, std::string message, std::string missingFile)
{
    mItems.push_back(Diagnostic{std::move(where), std::move(message), std::move(missingFile)});
}

void DiagnosticList::throwIfAny() const
{
    if (!mItems.empty()) throw UserError(mItems);
}

size_t editDistance(const std::string& a, const std::string& b)
{
    std::vector<size_t> row(b.size() + 1);
    std::iota(row.begin(), row.end(), size_t(0));
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            const size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
            row[j] = std::min({above + 1, row[j - 1] + 1, substitution});
            diagonal = above;
        }
    }
    return row[b.size()];
}

std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates)
{
    std::string best;
    size_t bestDistance = std::string::npos;
    for (const std::string& c : candidates) {
        const size_t d = editDistance(word, c);
        if (d < bestDistance) {
            bestDistance = d;
            best = c;
        }
    }
    // A typo changes a few characters; allow one edit per three characters, at least one edit.
    const size_t allowed = std::max<size_t>(1, std::max(word.size(), best.size()) / 3);
    return bestDistance <= allowed ? best : std::string();
}

} // namespace volmorph
