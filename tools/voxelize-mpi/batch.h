// A batch of vox-voxelize-mpi (--batch LIST -o DIR): the list read, each scene's output named, the folder made, and
// one scene voxelized exactly as vox-voxelize would. No MPI here (tests/voxelize_mpi_batch_test.cpp).
#pragma once

#include <string>
#include <vector>

#include "options.h"

namespace vox::mpi {

// The scenes of a batch list: one path a line (relative to the current folder), blank lines, trailing blanks and
// # comments skipped. Throws InputError when the list cannot be read or names no scene.
std::vector<std::string> readBatchList(const std::string& path);

// DIR/NAME.vgrid for each scene. Throws InputError for a line that names no file, UsageError when two scenes of one
// name would overwrite each other (`list` names the batch list in both).
std::vector<std::string> batchOutputs(const std::string& list, const std::vector<std::string>& scenes,
                                      const std::string& dir);

// Makes the output folder `dir` unless it exists. Throws OutputError when it is not a folder afterwards.
void makeOutputFolder(const std::string& dir);

// One scene of a batch: read, voxelized (and filled with --fill) and written to `output`, as vox-voxelize does.
// Throws as the library does; what the scene asks for is named with the scene.
void voxelizeOne(const Options& opt, const std::string& scenePath, const std::string& output);

}  // namespace vox::mpi
