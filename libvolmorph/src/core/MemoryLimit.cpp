#include <volmorph/core/MemoryLimit.h>

#include <unistd.h>

namespace volmorph {

uint64_t defaultMemoryLimitBytes()
{
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) return 4ull << 30;
    return uint64_t(pages) * uint64_t(pageSize) / 2;
}

uint64_t memoryLimitBytes(double gib)
{
    return gib > 0.0 ? uint64_t(gib * double(1ull << 30)) : defaultMemoryLimitBytes();
}

} // namespace volmorph
