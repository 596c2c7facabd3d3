#include "vox/core/memory_budget.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>

#include "vox/core/error.h"

namespace vox {

uint64_t memoryBudgetBytes() {
  if (const char* env = std::getenv("VOX_MEMORY_LIMIT_MB")) {
    char* end = nullptr;
    const unsigned long long mb = std::strtoull(env, &end, 10);
    if (end != env && *end == '\0' && mb > 0 && mb < (1ull << 40)) return mb << 20;
  }
  const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGE_SIZE);
  const uint64_t physical = pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) : (16ull << 30);
  return physical / 4 * 3;  // a quarter stays for the rest of the system
}

void checkMemory(double bytes, const std::string& where, const std::string& what) {
  const uint64_t budget = memoryBudgetBytes();
  if (!(bytes <= double(budget)))
    fail<LimitError>(where, ": ", what, " needs about ",
                     std::isfinite(bytes) ? uint64_t(bytes / (1 << 20)) : UINT64_MAX, " MiB, more than the ",
                     budget >> 20, " MiB allowed");
}

}  // namespace vox
