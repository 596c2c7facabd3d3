// libFuzzer target: grid files through vox::decodeGridFile, then a trace and an export (fuzz/fuzz_entry.h).
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vox::fuzz::decodeGridBytes({reinterpret_cast<const char*>(data), size});
  return 0;
}
