// The editor's page draws the pairs at t with its own interpolation (tools/editor/web/page/
// features.js, three.js's slerp): held here to the engine's (Feature.cpp's interpolate), through
// Node, at several t, for every type and for turns up to nearly half a turn. Skipped without node
// or the page's npm packages (tools/install-deps.sh installs both).
#include <volmorph/Feature.h>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <unistd.h>

using namespace volmorph;
using nlohmann::json;

namespace {

const std::filesystem::path kRoot = VOLMORPH_SOURCE_DIR;

json vec(const Vec3d& v)
{
    return json::array({v.x(), v.y(), v.z()});
}

json element(const FeatureElement& e)
{
    return {
        {"origin", vec(e.origin)}, {"axes", {vec(e.xAxis), vec(e.yAxis)}}, {"scale", vec(e.scale)}};
}

/// An element turned by `radians` about the unit axis `axis`, at `origin` with `scale`.
FeatureElement turned(const Vec3d& origin, Vec3d axis, double radians, const Vec3d& scale)
{
    axis.normalize();
    const openvdb::math::Mat3d r = openvdb::math::rotation<openvdb::math::Mat3d>(axis, radians);
    FeatureElement e;
    e.origin = origin;
    e.xAxis = r * Vec3d(1, 0, 0);
    e.yAxis = r * Vec3d(0, 1, 0);
    e.zAxis = e.xAxis.cross(e.yAxis);
    e.scale = scale;
    return e;
}

/// node's answer to `input`, parsed; null when node cannot run the page's module.
json runNode(const json& input)
{
    const std::filesystem::path dir = std::filesystem::temp_directory_path();
    const std::filesystem::path in =
        dir / ("volmorph-interp-" + std::to_string(::getpid()) + ".json");
    std::ofstream(in) << input.dump();
    const std::string command = "node " +
                                (kRoot / "tests" / "browser" / "interpolate.mjs").string() + " " +
                                in.string() + " 2>/dev/null";
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
    std::string text;
    char buffer[4096];
    while (pipe && std::fgets(buffer, sizeof buffer, pipe.get())) text += buffer;
    std::filesystem::remove(in);
    return json::parse(text, nullptr, false);
}

} // namespace

TEST(PageInterpolation, EqualsTheEngines)
{
    if (!std::filesystem::exists(kRoot / "tools" / "editor" / "web" / "node_modules" / "three") ||
        std::system("node --version >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "node or the page's npm packages are missing";
    const FeaturePairSpec pairs[] = {
        {FeatureType::Point,
         turned({0, 0, 0}, {0, 1, 0}, 0.0, {1, 1, 1}),
         turned({0.3, -0.2, 0.1}, {0, 1, 0}, 0.0, {1, 1, 1}),
         {}},
        {FeatureType::Segment,
         turned({0, 0.12, 0}, {0, 1, 0}, 0.0, {0.3, 0.1, 0.1}),
         turned({0, 0, 0}, {0, 1, 0}, 1.5707963267948966, {0.5, 0.1, 0.1}),
         {}},
        {FeatureType::Rectangle,
         turned({0.1, 0, 0}, {1, 1, 0}, 0.4, {0.2, 0.3, 1}),
         turned({-0.1, 0.2, 0}, {0, 0, 1}, 2.5, {0.4, 0.1, 1}),
         {}},
        {FeatureType::Box,
         turned({0, 0, 0}, {1, 2, 3}, -0.7, {0.5, 0.6, 0.7}),
         turned({0, 0.5, 0}, {3, -1, 2}, 3.1, {1.0, 0.2, 0.3}),
         {}},
    };
    const std::vector<double> ts = {0.0, 0.1, 0.25, 0.5, 0.8, 1.0};
    json input = {{"t", ts}, {"pairs", json::array()}};
    for (const FeaturePairSpec& p : pairs)
        input["pairs"].push_back({{"source", element(p.source)}, {"target", element(p.target)}});
    const json page = runNode(input);
    ASSERT_TRUE(page.is_array()) << "node did not run tests/browser/interpolate.mjs";
    ASSERT_EQ(page.size(), std::size(pairs));
    for (size_t i = 0; i < std::size(pairs); ++i) {
        const Feature a = Feature::fromElement(pairs[i].source, pairs[i].type),
                      b = Feature::fromElement(pairs[i].target, pairs[i].type);
        for (size_t k = 0; k < ts.size(); ++k) {
            const Feature e = interpolate(a, b, ts[k]);
            const json& got = page[i][k];
            const Vec3d expected[4] = {e.origin, e.x, e.y, e.scale};
            const json values[4] = {got["origin"], got["axes"][0], got["axes"][1], got["scale"]};
            for (int v = 0; v < 4; ++v)
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(values[v][c].get<double>(), expected[v][c], 1e-9)
                        << "pair " << i + 1 << " at t = " << ts[k] << ", part " << v << "[" << c
                        << "]";
        }
    }
}
