// The memory budget every estimate is checked against before an allocation that input decides. In core: the
// voxelizer, the renderer and the exporters check it as much as the readers do, and none of them reads files.
#pragma once

#include <cstdint>
#include <string>

namespace vox {

// Bytes the tools may spend on one request: three quarters of physical memory, or VOX_MEMORY_LIMIT_MB when that
// environment variable holds a positive number (tests use it to reach the limits quickly).
uint64_t memoryBudgetBytes();

// Throws LimitError "WHERE: WHAT needs N MiB, more than the M MiB allowed" when `bytes` exceeds memoryBudgetBytes().
// Called before an allocation whose size the input decides.
void checkMemory(double bytes, const std::string& where, const std::string& what);

}  // namespace vox
