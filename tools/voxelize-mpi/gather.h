// Every rank's report on rank 0 (the rank protocol's one collective; the reports themselves: rank_protocol.h).
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

#include "rank_protocol.h"

namespace vox::mpi {

// Collective over `comm`: every rank's outcome on rank 0, by rank (empty elsewhere).
inline std::vector<Outcome> gatherOutcomes(MPI_Comm comm, const Outcome& mine) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const std::string bytes = packOutcome(mine);
  const int length = int(bytes.size());
  std::vector<int> lengths(static_cast<size_t>(size)), offsets(static_cast<size_t>(size));
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, comm);
  std::string all;
  if (rank == 0) {
    size_t total = 0;
    for (int r = 0; r < size; ++r) {
      offsets[size_t(r)] = int(total);
      total += size_t(lengths[size_t(r)]);
    }
    all.resize(total);
  }
  MPI_Gatherv(bytes.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0, comm);
  std::vector<Outcome> out;
  if (rank == 0)
    for (int r = 0; r < size; ++r)
      out.push_back(unpackOutcome(all.substr(size_t(offsets[size_t(r)]), size_t(lengths[size_t(r)]))));
  return out;
}

}  // namespace vox::mpi
