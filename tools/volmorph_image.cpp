// libexec/volmorph/volmorph-image: every command, the image ones with OpenImageIO and Embree
// (bin/volmorph hands it every command line but the light commands', Main.h).
#include "Main.h"

namespace {

void addImageCommands(CLI::App& app, std::vector<volmorph::cli::Command>& commands)
{
    using namespace volmorph::cli;
    for (const auto add : {addCheckCommand, addRenderVdbCommand, addRenderCommand, addDiffCommand,
                           addPreviewCommand})
        commands.push_back(add(app));
}

} // namespace

int main(int argc, char** argv)
{
    return volmorph::cli::runVolmorph(argc, argv, addImageCommands);
}
