// libFuzzer target: every voxel writer (binvox, .vox, .vdb) and the voxel meshes on grids of crafted solid runs and
// occupied cells, from a grid file or a compact description (fuzz/voxel_writers_entry.h), under a 16 MiB budget.
#include "voxel_writers_entry.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  vox::fuzz::setWriterBudget();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vox::fuzz::runVoxelWritersInput({reinterpret_cast<const char*>(data), size});
  return 0;
}
