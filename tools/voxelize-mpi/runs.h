// The two runs of vox-voxelize-mpi, collective over MPI_COMM_WORLD: each returns the exit code, the same on every rank.
#pragma once

#include "options.h"

namespace vox::mpi {

// SCENE --bricks: the bricks of one scene's grid set handed out one at a time; rank 0 writes the manifest last.
int runSet(const Options& opt);
// --batch LIST: the listed scenes handed out one at a time, each into DIR/NAME.vgrid.
int runBatch(const Options& opt);

}  // namespace vox::mpi
