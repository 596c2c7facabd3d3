// The exporters' memory budget (export_budget.h).
#include "export/export_budget.h"

#include "vox/core/error.h"
#include "vox/core/memory_budget.h"

namespace vox {

void requireMemory(uint64_t bytes, const std::string& where, const std::string& what, const char* verb) {
  const uint64_t budget = memoryBudgetBytes();
  if (bytes <= budget) return;
  if (bytes == UINT64_MAX)
    fail<LimitError>(where, ": ", what, " ", verb, " 2^64 bytes or more, more than the ", budget >> 20, " MiB allowed");
  fail<LimitError>(where, ": ", what, " ", verb, " ", (bytes >> 20) + 1, " MiB, more than the ", budget >> 20,
                   " MiB allowed");
}

}  // namespace vox
