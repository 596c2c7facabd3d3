// The exports of vox-export besides meshes (main.cpp), and what they share: the grid's name put in front of the
// messages of a step that ran on a grid already read.
#pragma once

#include <chrono>
#include <new>
#include <stdexcept>
#include <string>

#include "options.h"
#include "vox/core/error.h"
#include "vox/export/voxel_format.h"

namespace vox::export_tool {

inline double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Runs an export step on a grid that has been read: the writers and mesh builders see a grid in memory and a stream,
// so their messages ("vox: ... voxels need ...", "grid: cell key ...") name no file; here each gets the grid's name
// in front, as every read error has (a message that already names it, such as a set's, is kept). Output errors name
// the output already. An allocation that failed anyway (std::bad_alloc, or std::length_error from a size beyond
// what a vector can hold) becomes the same kind of message, exit 2 as a LimitError.
template <typename F>
auto namingGrid(const Options& opt, F&& step) -> decltype(step()) {
  const auto named = [&](const char* what) {
    const std::string message = what;
    return message.find(opt.grid) != std::string::npos ? message : opt.grid + ": " + message;
  };
  try {
    return step();
  } catch (const OutputError&) {
    throw;
  } catch (const UsageError&) {
    throw;
  } catch (const LimitError& e) {
    throw LimitError(named(e.what()));
  } catch (const Error& e) {
    throw InputError(named(e.what()));
  } catch (const std::bad_alloc&) {
    fail<LimitError>(opt.grid, ": ", opt.output,
                     ": out of memory (the export needed more than estimated; try a smaller grid)");
  } catch (const std::length_error& e) {
    fail<LimitError>(opt.grid, ": ", opt.output, ": a size beyond what memory can hold (", e.what(), ")");
  }
}

// Voxel formats (.binvox, .vox, .vdb): the cells themselves, not a mesh; --faces and --ascii do not apply.
int runVoxelFormat(const Options& opt, VoxelFormat format);

// Whether `path` names a viewer page (.html, .htm, any case).
bool isViewerPagePath(const std::string& path);
// The viewer page (.html, vox/export/viewer_page.h): the merged surface, the cells and the scene's primitives in one
// self-contained page; --faces and --ascii do not apply (the page always draws the merged surface).
int runViewerPage(const Options& opt);

}  // namespace vox::export_tool
