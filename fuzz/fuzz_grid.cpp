// libFuzzer target: grid files through vox::decodeGridFile, then a trace and an export; and grid sets (a manifest,
// its scene file and bricks in one input, told apart by the manifest's magic) through the whole and the lazy set
// readers (fuzz/fuzz_entry.h). One target for both keeps scripts/fuzz.sh's time: libFuzzer's coverage feedback
// shares the target's 30 s between the two kinds of input.
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vox::fuzz::readGridInput({reinterpret_cast<const char*>(data), size});
  return 0;
}
