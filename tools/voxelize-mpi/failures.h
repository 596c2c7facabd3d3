// How vox-voxelize-mpi's ranks turn exceptions into what they report: an exit code and a message, phrased as
// vox-voxelize phrases them. No MPI here.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

#include "vox/core/error.h"
#include "vox/core/tool.h"

namespace vox::mpi {

// Runs body, turning an exception into the exit code and message vox::runTool would print.
inline int32_t capture(const std::function<void()>& body, std::string& message) {
  try {
    body();
    return kExitOk;
  } catch (...) {
    return currentExceptionExit(message);
  }
}

// Like vox-voxelize: what the scene asks for is named with the scene.
template <typename F>
auto namingScene(const std::string& scene, F&& f) {
  try {
    return f();
  } catch (const LimitError& e) {
    fail<LimitError>(scene, ": ", e.what());
  } catch (const InputError& e) {
    fail<InputError>(scene, ": ", e.what());
  }
}

// Every error line of every rank: the tools' one format (vox::errorLine: escaped, one line).
inline void printError(const std::string& message) {
  std::fputs(errorLine("vox-voxelize-mpi", message).c_str(), stderr);
}

}  // namespace vox::mpi
