#include <volmorph/Frames.h>

#include <OpenImageIO/filesystem.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <set>

namespace volmorph {
namespace {

/// The pattern in printf form: a run of N '#' becomes %0Nd. (OpenImageIO's parse_pattern reads
/// each '#' as four digits, the Nuke convention; scene files use one '#' per digit.)
std::string normalized(const std::string& pattern)
{
    const size_t hash = pattern.find('#');
    if (hash == std::string::npos) return pattern;
    size_t end = hash;
    while (end < pattern.size() && pattern[end] == '#') ++end;
    return pattern.substr(0, hash) + "%0" + std::to_string(end - hash) + "d" + pattern.substr(end);
}

} // namespace

std::string checkFramePattern(const std::string& pattern)
{
    const std::string p = normalized(pattern);
    if (p.find('#') != std::string::npos)
        return "only one run of '#' may stand for the frame number";
    int directives = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        if (p[i] != '%') continue;
        if (i + 1 < p.size() && p[i + 1] == '%') {
            ++i;
            continue;
        }
        size_t j = i + 1;
        while (j < p.size() && std::isdigit(static_cast<unsigned char>(p[j]))) ++j;
        if (j >= p.size() || p[j] != 'd')
            return "'%' must be followed by d or 0Nd (the frame number)";
        ++directives;
        i = j;
    }
    if (directives > 1) return "the frame number may appear only once";
    return "";
}

bool hasFramePlaceholder(const std::string& pattern)
{
    const std::string p = normalized(pattern);
    for (size_t i = 0; i < p.size(); ++i) {
        if (p[i] != '%') continue;
        if (i + 1 < p.size() && p[i + 1] == '%') {
            ++i; // a literal '%'
            continue;
        }
        size_t j = i + 1;
        while (j < p.size() && std::isdigit(static_cast<unsigned char>(p[j]))) ++j;
        if (j < p.size() && p[j] == 'd') return true;
    }
    return false;
}

std::vector<int> sequenceFrames(const std::string& pattern)
{
    std::vector<int> numbers;
    std::vector<std::string> names;
    if (!OIIO::Filesystem::scan_for_matching_filenames(normalized(pattern), numbers, names))
        return {};
    // Only names the pattern gives back exactly (its padding): "f.0001.vdb", not "f.1.vdb".
    std::vector<int> frames;
    for (size_t i = 0; i < numbers.size(); ++i)
        if (std::filesystem::path(frameFileName(pattern, numbers[i])).filename() ==
            std::filesystem::path(names[i]).filename())
            frames.push_back(numbers[i]);
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    return frames;
}

std::string frameFileName(const std::string& pattern, int frame)
{
    std::vector<std::string> names;
    OIIO::Filesystem::enumerate_file_sequence(normalized(pattern), {frame}, names);
    return names.empty() ? pattern : names.front();
}

std::vector<int> selectFrames(const FramesSpec& frames, const std::string& spec,
                              const std::string& what)
{
    std::vector<int> picked;
    if (spec.empty()) {
        for (int f = frames.first; f <= frames.last; ++f) picked.push_back(f);
        return picked;
    }
    std::vector<int> numbers;
    if (!OIIO::Filesystem::enumerate_sequence(spec, numbers) || numbers.empty())
        throw UserError(SourceLocation{what}, "cannot read the frame spec \"" + spec +
                                                  "\"; expected e.g. 1-10, 1-100x2 or 1,5,10-20");
    std::set<int> seen;
    for (int f : numbers) {
        if (f < frames.first || f > frames.last)
            throw UserError(SourceLocation{what},
                            "frame " + std::to_string(f) + " is outside the scene's range " +
                                std::to_string(frames.first) + "-" + std::to_string(frames.last));
        if (seen.insert(f).second) picked.push_back(f);
    }
    return picked;
}

std::string formatFrames(const std::vector<int>& frames)
{
    std::string out;
    for (size_t i = 0; i < frames.size();) {
        size_t j = i;
        while (j + 1 < frames.size() && frames[j + 1] == frames[j] + 1) ++j;
        if (!out.empty()) out += ',';
        out += std::to_string(frames[i]);
        if (j > i) out += '-' + std::to_string(frames[j]);
        i = j + 1;
    }
    return out;
}

int chunkCount(const std::vector<int>& frames, int chunkSize)
{
    if (chunkSize < 1) return 0;
    return int((frames.size() + size_t(chunkSize) - 1) / size_t(chunkSize));
}

std::vector<int> chunkFrames(const std::vector<int>& frames, int chunkSize, int index)
{
    if (chunkSize < 1 || index < 0 || index >= chunkCount(frames, chunkSize)) return {};
    const size_t first = size_t(index) * size_t(chunkSize);
    const size_t last = std::min(frames.size(), first + size_t(chunkSize));
    return std::vector<int>(frames.begin() + long(first), frames.begin() + long(last));
}

} // namespace volmorph
