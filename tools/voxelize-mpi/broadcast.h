// Rank 0's string on every rank (the set's generation folder, which rank 0 makes and every rank writes into).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>

namespace vox::mpi {

// Collective over `comm`: returns rank 0's `value` on every rank.
inline std::string broadcastString(MPI_Comm comm, const std::string& value) {
  uint64_t length = value.size();
  MPI_Bcast(&length, 1, MPI_UINT64_T, 0, comm);
  std::string out = value;
  out.resize(length);
  if (length > 0) MPI_Bcast(out.data(), int(length), MPI_CHAR, 0, comm);
  return out;
}

}  // namespace vox::mpi
