// libvox._voxelize_loop: the library's own loop over scenes, timed in C++, for bench/python_bench.py to measure what
// a Python call adds to the same work (not part of the public API).
#include <chrono>

#include "binding.h"
#include "vox/io/input_file.h"
#include "vox/voxelize/voxelize.h"

namespace voxpy {

namespace {

// Seconds that voxelizeScene takes over every scene of `sources` ((vertices, faces) pairs, converted before the
// clock starts) at `resolution`, one after the other, as a C++ program calling the library would.
double voxelizeLoop(const py::object& sources, const py::object& resolution, const py::object& threads) {
  if (!py::isinstance<py::list>(sources))
    failType("sources must be a list of (vertices, faces) pairs, not ", typeName(sources));
  std::vector<vox::Scene> scenes;
  for (const py::handle s : sources) {
    const auto pair = sequenceArg(s, "sources[" + std::to_string(scenes.size()) + "]", 2, "a (vertices, faces) pair");
    scenes.push_back(sceneFromArrays(pair[0], pair[1]));
  }
  vox::VoxelizeOptions vo;
  vo.resolution = uint32_t(intArg(resolution, "resolution", 1, vox::kMaxCellsPerAxis));
  vo.memoryLimitBytes = memoryBudget();
  Interrupt interrupt;
  return runLong(interrupt, threadsArg(threads), [&] {
    const auto start = std::chrono::steady_clock::now();
    size_t cells = 0;
    for (const vox::Scene& scene : scenes) cells += vox::voxelizeScene(scene, vo).occupiedCount();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return cells > 0 ? seconds : -1.0;
  });
}

}  // namespace

void bindBench(py::module_& m) {
  m.def("_voxelize_loop", &voxelizeLoop, py::arg("sources"), py::arg("resolution"), py::arg("threads") = py::none(),
        "Seconds of voxelizeScene over (vertices, faces) pairs in a C++ loop (bench/python_bench.py).");
}

}  // namespace voxpy
