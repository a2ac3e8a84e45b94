#include <volmorph/core/MemoryLimit.h>

#include <malloc.h>
#include <unistd.h>

#include <cstdio>

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

uint64_t residentBytes()
{
    malloc_trim(0);
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (!f) return 0;
    unsigned long long size = 0, resident = 0;
    const int read = std::fscanf(f, "%llu %llu", &size, &resident);
    std::fclose(f);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    return read == 2 && pageSize > 0 ? uint64_t(resident) * uint64_t(pageSize) : 0;
}

} // namespace volmorph
