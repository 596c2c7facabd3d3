// The module libvox._libvox; libvox/__init__.py re-exports it. One file per concept registers its part.
#include "binding.h"
#include "vox/core/tool.h"

PYBIND11_MODULE(_libvox, m) {
  m.doc() = "libvox: exact voxelization and exact grid ray tracing (the compiled part of the libvox package).";
  m.attr("__version__") = vox::versionString();
  voxpy::bindErrors(m);
  voxpy::GridClass grid = voxpy::bindGrid(m);
  voxpy::bindSave(grid);
  voxpy::bindMesh(grid);
  voxpy::bindRays(grid);
  voxpy::bindDistance(grid);
  voxpy::bindVoxelize(m);
  voxpy::bindRender(m);
  voxpy::bindBench(m);
  voxpy::nameBadCalls(m, grid);  // last: every function and method defined
  voxpy::nameBadCalls(grid, grid);
}
