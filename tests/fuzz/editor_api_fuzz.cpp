// libFuzzer target: the editor's JSON API (tools/editor/EditDocument.h). The first byte picks the
// edit (set, add, duplicate, delete, undo, redo), the rest is the request's body, parsed as
// EditorSession parses it; the edit is applied to a fresh copy of the sphere-to-box scene, then
// undone. Any input must give a new state or a BadRequest or Conflict, leaving the text as it
// was; a crash, a sanitizer report, a hang or any other exception is a bug.
#include "editor/EditDocument.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

std::filesystem::path scenePath;

/// sphere-to-box.toml with its mesh paths made absolute, in a temporary folder.
std::filesystem::path writeScene()
{
    const std::filesystem::path scenes = std::filesystem::path(VOLMORPH_SOURCE_DIR) / "scenes";
    std::ifstream in(scenes / "sphere-to-box.toml", std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    std::string s = text.str();
    const std::string from = "\"meshes/", to = "\"" + (scenes / "meshes").string() + "/";
    for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
        s.replace(at, from.size(), to);
    const auto path = std::filesystem::temp_directory_path() /
                      ("volmorph_fuzz_editor_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(path, std::ios::binary) << s;
    return path;
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    scenePath = writeScene();
    std::atexit([] { std::filesystem::remove(scenePath); });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    using namespace volmorph::editor;
    static const char* const kActions[] = {"set", "add", "duplicate", "delete", "undo", "redo"};
    if (size == 0) return 0;
    const std::string action = kActions[data[0] % 6];
    const std::string body(reinterpret_cast<const char*>(data) + 1, size - 1);
    static EditDocument pristine(scenePath);
    EditDocument document = pristine;
    const nlohmann::json request = nlohmann::json::parse(body, nullptr, false);
    if (request.is_discarded()) return 0; // answered 400 "malformed JSON"
    const std::string before = document.text();
    try {
        document.apply(action, request);
    } catch (const BadRequest&) {
        if (document.text() != before) std::abort(); // a refused edit changed the text
        return 0;
    } catch (const Conflict&) {
        return 0;
    }
    (void)document.state().dump();
    if (action != "undo" && action != "redo") {
        document.apply("undo", nlohmann::json::object());
        if (document.text() != before) std::abort(); // undo did not give the text back
    }
    return 0;
}
