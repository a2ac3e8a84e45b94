// The memory limit that large allocations (voxels, in-betweens, films) are checked against before
// they are made, so that a run too big for the machine is refused with a message, not killed.
#pragma once

#include <cstdint>

namespace volmorph {

/// Half of the machine's physical memory (4 GiB when it cannot be read).
uint64_t defaultMemoryLimitBytes();

/// A limit given in GiB (as the --memory-limit flags take it) in bytes; 0 means the default.
uint64_t memoryLimitBytes(double gib);

/// The process's resident memory now, after handing the allocator's free pages back to the system
/// (memory it would reuse is not counted); 0 when it cannot be read. For guards that add what a
/// stage will allocate to what is already held.
uint64_t residentBytes();

} // namespace volmorph
