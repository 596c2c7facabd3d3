// What the voxel_writers fuzz target runs (fuzz/fuzz_voxel_writers.cpp), shared with tests/voxel_formats_test.cpp so
// that a saved finding (tests/data/fuzz/voxel_writers/) replays through exactly the code that found it.
//
// Every voxel writer (binvox, MagicaVoxel .vox, OpenVDB .vdb) and the voxel meshes run on a grid built from the
// input, into memory or a sink that keeps no bytes, under a small memory budget. A writer may refuse the grid with
// vox::Error (a LimitError naming the estimate, an InputError for keys or runs that break the grid's rules); a crash,
// a sanitizer report, a hang (libFuzzer's -timeout), an allocation past -rss_limit_mb, an exception that is not a
// vox::Error (std::length_error "vector::reserve", std::bad_alloc), a message on more than one line, or a writer that
// writes another number of voxels than the grid holds is a finding.
//
// The input is either a grid file (magic "VOXGRID\n"; header size and checksum fixed first, as the grid target
// does), or a compact description that reaches huge and odd solid runs in a few bytes:
//   byte 0         flags: bit 0 keep the records as they are (else they are made valid: sorted, in range, runs
//                  merged), bits 1-2 the colour mode of .vox and the meshes (count, material, none)
//   bytes 1 .. 12  three u32 dims: n = 1 + ((v >> 8) mod 2^b), b = (v & 0xff) mod 22, so 1 .. 2^21 cells per axis,
//                  small ones as likely as huge ones
//   then records of 17 bytes: u8 kind, u64 a, u64 b (little-endian). Even kind: a solid run, first a, count b.
//   Odd kind: an occupied cell, key a, with 1 + b mod 4 primitives.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_entry.h"
#include "vox/core/error.h"
#include "vox/export/binvox_writer.h"
#include "vox/export/magicavoxel_writer.h"
#include "vox/export/vdb_writer.h"
#include "vox/export/voxel_mesh.h"
#include "vox/export/voxel_runs.h"
#include "vox/io/grid_file.h"

namespace vox::fuzz {

// The budget the target runs under (VOX_MEMORY_LIMIT_MB unless the environment sets it): small enough that every
// estimate's refusal is reached and that what fits is quick under the sanitizers (a .vdb tree of 256 MiB, some
// 50,000 dense leaves, took 10 s there), large enough for grids of some thousands of voxels.
inline constexpr const char* kWriterBudgetMb = "16";

// Bytes a writer may send to the sink before the harness stops it: the writers' time past their estimates is their
// output's (binvox writes a cube of D^3 bits, up to 540 MB at 4096^3), which says nothing new after a MiB.
inline constexpr uint64_t kSinkBytes = uint64_t(1) << 20;

// Thrown by the sink when the writer has written kSinkBytes: ends that writer's run without a finding.
struct SinkFull {};

// A stream buffer that counts and drops what is written.
class CountingSink : public std::streambuf {
 public:
  uint64_t bytes() const { return bytes_; }

 protected:
  std::streamsize xsputn(const char*, std::streamsize n) override {
    count(uint64_t(n));
    return n;
  }
  int_type overflow(int_type c) override {
    count(1);
    return traits_type::not_eof(c);
  }

 private:
  void count(uint64_t n) {
    bytes_ += n;
    if (bytes_ > kSinkBytes) throw SinkFull{};
  }
  uint64_t bytes_ = 0;
};

inline uint64_t readU64(std::string_view bytes, size_t at) {
  uint64_t v = 0;
  std::memcpy(&v, bytes.data() + at, 8);
  return v;
}

// The grid and colour mode of a compact input (above).
struct WriterInput {
  Grid grid;
  ColorMode color = ColorMode::Count;
};

// Decodes a compact input into `in`; false when it is too short to hold the dims.
inline bool decodeCompactInput(std::string_view bytes, WriterInput& in) {
  if (bytes.size() < 13) return false;
  const uint8_t flags = uint8_t(bytes[0]);
  const bool raw = flags & 1;
  in.color = std::array<ColorMode, 4>{ColorMode::Count, ColorMode::Material, ColorMode::None,
                                      ColorMode::Count}[(flags >> 1) & 3];
  Grid& g = in.grid;
  for (int a = 0; a < 3; ++a) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + 1 + 4 * a, 4);
    const uint32_t bits = (v & 0xff) % 22;
    g.dims[a] = 1 + ((v >> 8) & ((uint32_t(1) << bits) - 1));
    g.bounds.lo.at(a) = -1;
    g.bounds.hi.at(a) = -1 + 0.5 * g.dims[a];
  }
  const uint64_t cells = g.cellCount();  // at most 2^63
  std::vector<std::pair<uint64_t, uint32_t>> occupied;
  std::vector<CellRun> runs;
  for (size_t at = 13; at + 17 <= bytes.size(); at += 17) {
    const uint8_t kind = uint8_t(bytes[at]);
    const uint64_t a = readU64(bytes, at + 1), b = readU64(bytes, at + 9);
    if (kind & 1) {
      occupied.push_back({raw ? a : a % cells, uint32_t(1 + b % 4)});
    } else if (raw) {
      runs.push_back({a, b});
    } else {
      const uint64_t first = a % cells;
      runs.push_back({first, 1 + b % (cells - first)});
    }
  }
  if (!raw) {
    std::sort(occupied.begin(), occupied.end());
    occupied.erase(
        std::unique(occupied.begin(), occupied.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
        occupied.end());
    std::sort(runs.begin(), runs.end(), [](const CellRun& x, const CellRun& y) { return x.first < y.first; });
    std::vector<CellRun> merged;
    for (const CellRun& r : runs) {  // overlapping or touching runs become one, as a grid file must hold them
      if (!merged.empty() && r.first <= merged.back().first + merged.back().count) {
        merged.back().count = std::max(merged.back().count, r.first + r.count - merged.back().first);
      } else {
        merged.push_back(r);
      }
    }
    runs = std::move(merged);
  }
  for (const auto& [key, prims] : occupied) {
    g.cellKeys.push_back(key);
    for (uint32_t p = 0; p < prims; ++p) g.primIds.push_back(p);
    g.cellStart.push_back(g.primIds.size());
  }
  g.solidRuns = std::move(runs);
  return true;
}

// A scene for ColorMode::Material: four triangles of two materials, so that primitive ids 0..3 are valid.
inline Scene writerScene() {
  Scene s;
  s.materials.resize(2);
  s.materials[0].diffuse = {0.8, 0.1, 0.1};
  s.materials[1].diffuse = {0.1, 0.1, 0.8};
  for (uint32_t t = 0; t < 4; ++t) {
    Triangle tri;
    tri.v = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, double(t)}};
    tri.material = t % 2;
    s.triangles.push_back(tri);
  }
  return s;
}

// A message the tools would print must be one line.
inline void checkWriterError(const Error& e, const char* writer) {
  if (std::strchr(e.what(), '\n')) {
    std::fprintf(stderr, "%s: a message on more than one line: %s\n", writer, e.what());
    std::abort();
  }
}

inline void checkVoxelCount(const char* writer, uint64_t written, uint64_t expected) {
  if (written != expected) {
    std::fprintf(stderr, "%s wrote %llu voxels, the grid holds %llu\n", writer, (unsigned long long)written,
                 (unsigned long long)expected);
    std::abort();
  }
}

// Runs `write`; vox::Error and a full sink end it, anything else escapes to libFuzzer (a finding).
template <typename F>
void runWriter(const char* writer, F&& write) {
  try {
    write();
  } catch (const SinkFull&) {
  } catch (const Error& e) {
    checkWriterError(e, writer);
  }
}

// Every writer on `grid`. The grid's tally (from its runs, without expanding them) decides what is run only where
// a writer's legitimate work is its output: .vox needs 4 bytes a voxel and the meshes tens, so they run on grids of
// up to 2^14 voxels, and on larger ones only when their estimates must refuse them (over 2^29 voxels: past .vox's
// 2^31 bytes and the budget), where a hang is a finding; binvox visits every row of its cube twice (up to 2^24), so
// it runs up to 2^16 rows, and beyond when its dimension must be refused. Grids that break the rules go to every
// writer (each checks the keys and runs before its first row). .vdb always runs: its work is bounded by the runs
// and its estimate.
inline void exerciseVoxelWriters(const Grid& grid, const Scene& scene, ColorMode color) {
  VoxelTally tally{UINT64_MAX, UINT64_MAX};
  try {
    tally = tallyVoxels(grid);
  } catch (const Error& e) {  // keys or runs that break the grid's rules: every writer must refuse them too
    checkWriterError(e, "tallyVoxels");
  }
  const uint64_t voxels = tally.voxels;
  const bool invalid = voxels == UINT64_MAX;
  const bool small = voxels <= (uint64_t(1) << 14);
  const bool huge = !invalid && voxels > (uint64_t(1) << 29);
  if (invalid || tally.rows <= (uint64_t(1) << 16) ||
      std::max({grid.dims[0], grid.dims[1], grid.dims[2]}) > kBinvoxMaxDim)
    runWriter("binvox", [&] {
      CountingSink sink;
      std::ostream out(&sink);
      writeBinvox(out, grid);
    });
  if (small || huge || invalid) {
    runWriter("vox", [&] {
      CountingSink sink;
      std::ostream out(&sink);
      const std::vector<Rgb8> colors = occupiedCellColors(grid, scene, color);
      checkVoxelCount("vox", writeMagicaVoxel(out, grid, colors, kSolidCellColor).voxels, voxels);
    });
    for (FaceMode faces : {FaceMode::Exposed, FaceMode::Merged, FaceMode::All})
      runWriter("voxel mesh", [&] {
        VoxelMeshStats stats;
        buildVoxelMesh(grid, scene, faces, color, &stats);
        checkVoxelCount("voxel mesh", stats.voxels, voxels);
      });
  }
  runWriter("vdb", [&] {
    CountingSink sink;
    std::ostream out(&sink);
    checkVoxelCount("vdb", writeVdb(out, grid).activeVoxels, voxels);
  });
}

inline void setWriterBudget() { ::setenv("VOX_MEMORY_LIMIT_MB", kWriterBudgetMb, 0); }

// The target's input: a grid file or a compact description (above).
inline void runVoxelWritersInput(std::string_view bytes) {
  if (bytes.size() >= 8 && bytes.substr(0, 8) == std::string_view("VOXGRID\n", 8)) {
    std::string file(bytes);
    fixHeader(file);
    GridFile decoded;
    try {
      decoded = decodeGridFile(file, "fuzz.vgrid");
    } catch (const Error&) {
      return;
    }
    exerciseVoxelWriters(decoded.grid, decoded.scene, ColorMode::Count);
    return;
  }
  WriterInput in;
  if (!decodeCompactInput(bytes, in)) return;
  static const Scene scene = writerScene();
  exerciseVoxelWriters(in.grid, scene, in.color);
}

}  // namespace vox::fuzz
