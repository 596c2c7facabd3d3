// The exporters' memory budget (export_budget.h).
#include "export/export_budget.h"

#include "vox/core/error.h"
#include "vox/io/input_file.h"

namespace vox {

void requireMemory(uint64_t bytes, const std::string& where, const std::string& what) {
  const uint64_t budget = memoryBudgetBytes();
  if (bytes <= budget) return;
  if (bytes == UINT64_MAX)
    fail<LimitError>(where, ": ", what, " needs more than 2^64 bytes, more than the ", budget >> 20, " MiB allowed");
  fail<LimitError>(where, ": ", what, " needs about ", (bytes >> 20) + 1, " MiB, more than the ", budget >> 20,
                   " MiB allowed");
}

}  // namespace vox
