// The memory limit that large allocations (voxels, in-betweens, films) are checked against before
// they are made, so that a run too big for the machine is refused with a message, not killed.
#pragma once

#include <volmorph/core/Diagnostics.h>

#include <cstdint>
#include <string>
#include <utility>

namespace volmorph {

/// Half of the machine's physical memory (4 GiB when it cannot be read).
uint64_t defaultMemoryLimitBytes();

/// A limit given in GiB in bytes; 0 means the default.
uint64_t memoryLimitBytes(double gib);

/// The process's resident memory now, after handing the allocator's free pages back to the system
/// (memory it would reuse is not counted); 0 when it cannot be read. For guards that add what a
/// stage will allocate to what is already held.
uint64_t residentBytes();

/// A request past the memory limit, refused before it is allocated: a user error whose message
/// says what was asked, the limit and what to make smaller, and ends "raise the memory limit". It
/// names no way to raise it: each front end says its own (the CLI's flag, the Python module's
/// keyword argument), with neededBytes() and limitBytes() if it wants the figures.
class MemoryLimitExceeded : public UserError {
public:
    MemoryLimitExceeded(SourceLocation where, std::string message, uint64_t neededBytes,
                        uint64_t limitBytes)
        : UserError(std::move(where), std::move(message)), mNeeded(neededBytes), mLimit(limitBytes)
    {
    }
    uint64_t neededBytes() const { return mNeeded; }
    uint64_t limitBytes() const { return mLimit; }

private:
    uint64_t mNeeded, mLimit;
};

} // namespace volmorph
