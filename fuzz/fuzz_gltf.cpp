// libFuzzer target: glTF JSON files through vox::loadScene (fuzz/fuzz_entry.h).
#include "fuzz_entry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vox::fuzz::loadSceneBytes({reinterpret_cast<const char*>(data), size}, "gltf");
  return 0;
}
