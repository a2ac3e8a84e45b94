// SceneDocument (volmorph/SceneDocument.h): edits that keep every other byte of the user's file, on
// the default scene as written by hand (comments, aligned columns, inline tables).
#include <volmorph/Scene.h>
#include <volmorph/SceneDocument.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

using namespace volmorph;

namespace {

const std::filesystem::path kRoot = VOLMORPH_SOURCE_DIR;
const std::filesystem::path kScene = kRoot / "scenes" / "bunny-to-knot.toml";

std::vector<std::string> linesOf(const std::string& text)
{
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

/// The lines of `a` that `b` lacks, and of `b` that `a` lacks, line for line (same count).
int changedLines(const std::string& a, const std::string& b)
{
    const auto la = linesOf(a), lb = linesOf(b);
    if (la.size() != lb.size()) return -1;
    int changed = 0;
    for (size_t i = 0; i < la.size(); ++i) changed += la[i] != lb[i];
    return changed;
}

int countOf(const std::string& text, const std::string& what)
{
    int n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

} // namespace

TEST(SceneDocument, ChangingOneValueChangesOnlyItsLine)
{
    SceneDocument doc = SceneDocument::read(kScene);
    const std::string before = doc.text();
    doc.set("pair[2].target.origin", tomlArray({-0.4, 0.425, 0.0}));
    EXPECT_EQ(changedLines(before, doc.text()), 1);
    const Scene scene = parseScene(doc.text(), kScene);
    EXPECT_EQ(scene.pairs[1].target.origin, Vec3d(-0.4, 0.425, 0.0));
    EXPECT_EQ(scene.pairs[1].source.origin, Vec3d(-0.48, 0.55, 0.15)); // beside it, untouched
    EXPECT_EQ(countOf(doc.text(), "#"), countOf(before, "#"));
    // The line keeps its own layout around the value.
    EXPECT_NE(doc.text().find("target = { origin = [-0.4, 0.425, 0.0] }"), std::string::npos);
    // A header table's value, and back: the text is the original byte for byte.
    doc.set("warp.epsilon", "0.05");
    EXPECT_DOUBLE_EQ(parseScene(doc.text(), kScene).warp.epsilon, 0.05);
    doc.set("warp.epsilon", "0.02");
    doc.set("pair[2].target.origin", "[-0.45, 0.40, 0.0]");
    EXPECT_EQ(doc.text(), before);
}

TEST(SceneDocument, AKeyATableLacksIsAddedInsideIt)
{
    SceneDocument doc = SceneDocument::read(kScene);
    const std::string before = doc.text();
    // Inside an inline table: before its closing brace, on its line.
    doc.set("pair[1].source.weight", "2.0");
    EXPECT_EQ(changedLines(before, doc.text()), 1);
    EXPECT_NE(doc.text().find("scale = [0.8, 0.6, 0.55], weight = 2.0 }"), std::string::npos);
    // In a [table]: a line after its last key.
    SceneDocument second = SceneDocument::read(kScene);
    second.set("warp.weighting", "\"beier-neely\"");
    const auto lines = linesOf(second.text());
    const auto at = std::find(lines.begin(), lines.end(), "weighting = \"beier-neely\"");
    ASSERT_NE(at, lines.end());
    EXPECT_EQ(std::prev(at)->rfind("tolerance = 0.25", 0), 0u);
    EXPECT_EQ(lines.size(), linesOf(before).size() + 1);
    EXPECT_EQ(parseScene(second.text(), kScene).warp.weighting, Weighting::BeierNeely);
}

TEST(SceneDocument, PairsAreAppendedAfterTheLastAndRemovedWithTheirComment)
{
    SceneDocument doc = SceneDocument::read(kScene);
    const std::string before = doc.text();
    ASSERT_EQ(doc.pairCount(), 3);
    doc.appendPair({"type = \"point\"", "source = { origin = " + tomlArray({0.1, 0.9, 0.0}) + " }",
                    "target = { origin = " + tomlArray({0.0, 0.95, 0.0}) + " }"},
                   {"suggested by volmorph pairs suggest"});
    EXPECT_EQ(doc.pairCount(), 4);
    const Scene scene = parseScene(doc.text(), kScene);
    ASSERT_EQ(scene.pairs.size(), 4u);
    EXPECT_EQ(scene.pairs[3].target.origin, Vec3d(0.0, 0.95, 0.0));
    // Every original line is still there, in order: the new ones were inserted as one block.
    const auto was = linesOf(before), is = linesOf(doc.text());
    size_t i = 0;
    for (const std::string& line : is)
        if (i < was.size() && line == was[i]) ++i;
    EXPECT_EQ(i, was.size());
    // It sits after the third pair, before [warp].
    EXPECT_LT(doc.text().find("suggested by volmorph"), doc.text().find("[warp]"));
    EXPECT_GT(doc.text().find("suggested by volmorph"), doc.text().find("[0.47, 0.25, 0.08]"));
    // Removing it gives the original back.
    doc.removePair(4);
    EXPECT_EQ(doc.text(), before);
    // The second pair goes with the comment above it; the others keep theirs.
    doc.removePair(2);
    EXPECT_EQ(doc.pairCount(), 2);
    EXPECT_EQ(doc.text().find("Nose to the left lobe"), std::string::npos);
    EXPECT_NE(doc.text().find("No pair for the ears"), std::string::npos);
    EXPECT_NO_THROW(parseScene(doc.text(), kScene));
}

TEST(SceneDocument, BadEditsAreRefusedAndLeaveTheTextAsItWas)
{
    SceneDocument doc = SceneDocument::read(kScene);
    const std::string before = doc.text();
    EXPECT_THROW(doc.set("pair[2].target.origin", "[1, 2,"), std::invalid_argument);
    EXPECT_THROW(doc.set("pair[9].target.origin", "[1, 2, 3]"), std::invalid_argument);
    EXPECT_THROW(doc.set("nosuch.table.key", "1"), std::invalid_argument);
    EXPECT_THROW(doc.set("pair[0].type", "\"box\""), std::invalid_argument);
    EXPECT_THROW(doc.removePair(4), std::invalid_argument);
    EXPECT_THROW(doc.appendPair({"type = "}), std::invalid_argument);
    EXPECT_EQ(doc.text(), before);
    EXPECT_THROW(SceneDocument("[a\nb = 1"), UserError);
}

TEST(SceneDocument, SavesAtomicallyAndReadsBackTheSameBytes)
{
    const auto dir = std::filesystem::temp_directory_path() / "volmorph_scene_document_test";
    std::filesystem::create_directories(dir);
    SceneDocument doc = SceneDocument::read(kScene);
    doc.set("render.samples", "16");
    doc.save(dir / "scene.toml");
    EXPECT_EQ(SceneDocument::read(dir / "scene.toml").text(), doc.text());
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(entry.path().filename(), "scene.toml") << "a temporary file was left";
}

TEST(SceneDocument, NumbersAreWrittenToReadBackExactly)
{
    for (const double v : {0.0, 0.5, 3.0, -2.0, 0.1, 1e-7, 123456.789, 1.0 / 3.0}) {
        const std::string text = tomlNumber(v);
        EXPECT_EQ(std::stod(text), v) << text;
        EXPECT_NE(text.find_first_of(".e"), std::string::npos) << text;
    }
    EXPECT_EQ(tomlNumber(3.0), "3.0");
    EXPECT_EQ(tomlArray({1.0, 0.25}), "[1.0, 0.25]");
}

TEST(SceneDocument, RoundedNumbersOfAnySizeReadBack)
{
    EXPECT_EQ(tomlRounded(0.123456), "0.1235");
    EXPECT_EQ(tomlRounded(-0.00001), "0.0");
    EXPECT_EQ(tomlRounded(2.0), "2.0");
    // Found by the editor's fuzzer: "%.4f" wrote 1e92's hundred digits, which no TOML reader takes.
    for (const double v : {123456789.125, 1e11, -3.5e15, 9.9e92, 1.7e308, -4e200}) {
        SceneDocument doc("[a]\nb = 1.0\n");
        ASSERT_NO_THROW(doc.set("a.b", tomlRounded(v))) << tomlRounded(v);
        EXPECT_EQ(std::stod(tomlRounded(v)), std::abs(v) < 1e11 ? std::round(v * 1e4) / 1e4 : v);
    }
}

TEST(SceneDocument, AFileWithWindowsLineEndingsKeepsThem)
{
    std::ifstream in(kScene, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    std::string crlf;
    for (const char c : text.str()) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    SceneDocument doc(crlf, kScene);
    doc.set("pair[2].target.origin", "[-0.4, 0.425, 0.0]");
    doc.set("warp.weighting", "\"beier-neely\"");
    doc.appendPair({"type = \"point\"", "source = { origin = [0.0, 1.0, 0.0] }",
                    "target = { origin = [0.0, 1.0, 0.0] }"});
    // Every line still ends in CR LF: no bare LF anywhere.
    for (size_t i = 0; i < doc.text().size(); ++i) {
        if (doc.text()[i] == '\n') {
            ASSERT_TRUE(i > 0 && doc.text()[i - 1] == '\r') << "at " << i;
        }
    }
    const Scene scene = parseScene(doc.text(), kScene);
    EXPECT_EQ(scene.pairs.size(), 4u);
    doc.removePair(4);
    doc.set("warp.epsilon", "0.02");
    EXPECT_EQ(parseScene(doc.text(), kScene).pairs.size(), 3u);
    EXPECT_EQ(doc.text().find("\r\n\r\n\r\n"), std::string::npos);
}
