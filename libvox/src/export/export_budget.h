// The memory budget of the exporters, for estimates computed with checked arithmetic (vox/core/checked_math.h): an
// estimate that saturated is refused like any other too-large one, with a message that says so instead of a
// wrapped number.
#pragma once

#include <cstdint>
#include <string>

namespace vox {

// Throws LimitError "WHERE: WHAT needs about N MiB, more than the M MiB allowed" (N "2^64 bytes or more" for a
// saturated estimate, UINT64_MAX) when `bytes` exceeds memoryBudgetBytes(). `verb` replaces "needs about" (an
// estimate checked as it grows says "need at least"). Called before the allocation the estimate guards.
void requireMemory(uint64_t bytes, const std::string& where, const std::string& what, const char* verb = "needs about");

}  // namespace vox
