// The rank protocol of vox-voxelize-mpi: what each rank reports to rank 0 once its work is done, packed to bytes for
// MPI_Gatherv (gather.h), and what rank 0 makes of every rank's report. No MPI here, so that one process can test it
// (tests/voxelize_mpi_rank_protocol_test.cpp).
#pragma once

#include <compare>
#include <cstdint>
#include <string>
#include <vector>

#include "vox/io/grid_set.h"

namespace vox::mpi {

// One scene of a batch and its own outcome (a bad scene fails itself, not the rank).
struct SceneResult {
  uint64_t index = 0;  // in the batch list
  int32_t code = 0;    // exit code: 0 ok
  std::string message;
  auto operator<=>(const SceneResult&) const = default;
};

// What one rank reports: its first failure (code 0: none), its counters, and the items it finished (bricks of a set,
// or scenes of a batch).
struct Outcome {
  int32_t code = 0;
  std::string message;
  double seconds = 0, peakMb = 0;
  uint64_t items = 0;
  std::vector<BrickEntry> bricks;
  std::vector<SceneResult> scenes;
};

// The peak resident memory of this process, in MiB (Outcome::peakMb).
double peakMemoryMb();

// Plain bytes: both ends are this program, so no versioning. unpackOutcome(packOutcome(o)) equals o; bytes from
// anything else are a programmer error (VOX_CHECK).
std::string packOutcome(const Outcome& o);
Outcome unpackOutcome(const std::string& bytes);

// A set run fails with the first failing rank's code; `message` gets its message, prefixed "rank R: " when there
// is more than one rank. 0 when every rank succeeded.
int32_t setFailure(const std::vector<Outcome>& all, std::string& message);

// The manifest of a set whose bricks every rank wrote: `set` (plan, bricks, scene file) with every rank's entries,
// those without cells left out, ascending by brick number.
GridSetManifest mergeBrickEntries(const GridSetManifest& set, const std::vector<Outcome>& all);

// A batch run: every failed scene's message in batch order, and the exit code, the largest of theirs (0 when none).
struct BatchSummary {
  int code = 0;
  std::vector<std::string> errors;
};
BatchSummary summarizeBatch(const std::vector<Outcome>& all);

// --stats: one line per rank (items, work seconds, peak memory), then the rank count, the run's seconds and the
// largest peak, as "name: value" lines.
std::string rankStatsText(const std::vector<Outcome>& all, double totalSeconds);

}  // namespace vox::mpi
