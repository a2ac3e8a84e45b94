// bin/volmorph: the light commands here; every other command line (the image commands, --help,
// --version, a mistyped command) to libexec/volmorph/volmorph-image, by exec (Main.h says why).
#include "Main.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

int main(int argc, char** argv)
{
    using namespace volmorph::cli;
    if (argc > 1)
        for (const char* name : kLightCommands)
            if (std::strcmp(argv[1], name) == 0) return runVolmorph(argc, argv, nullptr);
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path image =
        self.parent_path().parent_path() / "libexec" / "volmorph" / "volmorph-image";
    ::execv(image.c_str(), argv); // returns only on failure
    std::fprintf(stderr, "volmorph: cannot run %s (%s): the installation is incomplete\n",
                 image.c_str(), std::strerror(errno));
    return kExitInternal;
}
