#include <volmorph/core/Version.h>

namespace volmorph {

const char* versionString()
{
    return VOLMORPH_VERSION_STRING;
}

} // namespace volmorph
