#include <volmorph/core/Diagnostics.h>

#include <gtest/gtest.h>

using namespace volmorph;

TEST(Diagnostics, FormatsFileLineColumn)
{
    EXPECT_EQ((Diagnostic{{"a.toml", 3, 7}, "bad"}).str(), "a.toml:3:7: bad");
    EXPECT_EQ((Diagnostic{{"a.toml", 3, 0}, "bad"}).str(), "a.toml:3: bad");
    EXPECT_EQ((Diagnostic{{"a.toml", 0, 0}, "bad"}).str(), "a.toml: bad");
}

TEST(Diagnostics, UserErrorKeepsEveryDiagnostic)
{
    DiagnosticList list;
    EXPECT_NO_THROW(list.throwIfAny());
    list.error({"f", 1, 2}, "first");
    list.error({"f", 3, 4}, "second");
    try {
        list.throwIfAny();
        FAIL() << "expected a UserError";
    } catch (const UserError& e) {
        ASSERT_EQ(e.diagnostics().size(), 2u);
        EXPECT_EQ(std::string(e.what()), "f:1:2: first\nf:3:4: second");
    }
}

TEST(Diagnostics, EditDistance)
{
    EXPECT_EQ(editDistance("", ""), 0u);
    EXPECT_EQ(editDistance("abc", ""), 3u);
    EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
    EXPECT_EQ(editDistance("voxle_size", "voxel_size"), 2u);
}

TEST(Diagnostics, ClosestMatchSuggestsOnlyPlausibleTypos)
{
    const std::vector<std::string> keys = {"voxel_size", "resolution"};
    EXPECT_EQ(closestMatch("voxle_size", keys), "voxel_size");
    EXPECT_EQ(closestMatch("resolutoin", keys), "resolution");
    EXPECT_EQ(closestMatch("camera", keys), "");
    EXPECT_EQ(closestMatch("x", {"a", "bb"}), "a"); // one edit is always allowed
}
