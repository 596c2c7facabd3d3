// binvox writer (binvox_writer.h). The format's order (x slowest, then z, then y) is the transpose of our keys
// (x fastest), so the cube is swept plane by plane along x: each voxel row of the grid (a run along x at fixed
// j, k) turns bit k*D + j of the plane on where it starts and off where it ends, and each plane is run-length
// encoded from its bit words. Planes are visited in x order, and the bits within a plane in z-then-y order, which is
// exactly binvox's index x*D*D + z*D + y.
// Format: https://www.patrickmin.com/binvox/binvox.html and binvox-rw-py (read_as_3d_array: values and counts
// alternate; the flat array is reshaped to (D, D, D) and transposed (0, 2, 1) to x, y, z).
#include "vox/export/binvox_writer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "export/export_budget.h"
#include "vox/core/checked_math.h"
#include "vox/core/error.h"
#include "vox/export/voxel_runs.h"

namespace vox {

namespace {

// Run-length encoder of a bit stream into binvox (value, count) pairs; runs longer than 255 are split.
class RunEncoder {
 public:
  explicit RunEncoder(std::ostream& out) : out_(out) {}
  void add(bool value, uint64_t n) {
    if (n == 0) return;
    if (value != value_) {
      emit();
      value_ = value;
    }
    count_ += n;
  }
  void finish() {
    emit();
    flushBuffer();
  }

 private:
  void emit() {
    // Whole pairs of 255 in blocks: an empty or full cube of 4096^3 is 2^28 of them, which one push per pair made
    // seconds of the export.
    const std::string block = std::string(1, char(value_ ? 1 : 0)) + char(255);
    while (count_ >= 255 * kBlockPairs) {
      if (pairs_.size() != 2 * kBlockPairs || pairs_[0] != block[0])
        for (pairs_.clear(); pairs_.size() < 2 * kBlockPairs;) pairs_ += block;
      buffer_ += pairs_;
      count_ -= 255 * kBlockPairs;
      if (buffer_.size() >= (1u << 20)) flushBuffer();
    }
    while (count_ > 0) {
      const uint64_t n = std::min<uint64_t>(count_, 255);
      buffer_.push_back(char(value_ ? 1 : 0));
      buffer_.push_back(char(uint8_t(n)));
      count_ -= n;
      if (buffer_.size() >= (1u << 20)) flushBuffer();
    }
  }
  void flushBuffer() {
    out_.write(buffer_.data(), std::streamsize(buffer_.size()));
    buffer_.clear();
  }
  static constexpr uint64_t kBlockPairs = 4096;
  std::ostream& out_;
  std::string buffer_;
  std::string pairs_;  // kBlockPairs pairs (value, 255) of the last value emitted in blocks
  bool value_ = false;
  uint64_t count_ = 0;
};

// Encodes the plane `words` (the first `nbits` bits, `setBits` of them set) in order. Only the words in `active`
// (ascending) are ever set; the others are runs of zeros, added without being read, so a plane costs its active
// words, not D^2 / 64 (a grid of a few rows in a 4096 cube has thousands of mostly empty planes).
void encodePlane(const std::vector<uint64_t>& words, uint64_t nbits, uint64_t setBits,
                 const std::vector<uint32_t>& active, RunEncoder& enc) {
  if (setBits == 0 || setBits == nbits) return enc.add(setBits != 0, nbits);  // without reading a word
  uint64_t done = 0;                                                          // bits encoded
  for (const uint32_t w : active) {
    const uint64_t start = 64 * uint64_t(w);
    enc.add(false, start - done);
    const unsigned valid = unsigned(std::min<uint64_t>(64, nbits - start));
    done = start + valid;
    uint64_t word = words[w];
    if (word == 0 || (valid == 64 && word == ~uint64_t(0))) {
      enc.add(word != 0, valid);
      continue;
    }
    unsigned used = 0;
    while (used < valid) {
      const bool bit = word & 1;
      unsigned n = bit ? unsigned(std::countr_one(word)) : unsigned(std::countr_zero(word));
      n = std::min(n, valid - used);
      enc.add(bit, n);
      used += n;
      word = n >= 64 ? 0 : word >> n;
    }
  }
  enc.add(false, nbits - done);
}

}  // namespace

BinvoxLayout binvoxLayout(const Grid& grid) {
  BinvoxLayout layout;
  const auto& n = grid.dims;
  layout.dim = std::max({n[0], n[1], n[2]});
  if (layout.dim > kBinvoxMaxDim)
    fail<LimitError>("binvox: the grid's ", layout.dim, " cells on its longest axis exceed the ", kBinvoxMaxDim,
                     " that binvox readers can expand densely");
  int longest = 0;
  for (int a = 1; a < 3; ++a)
    if (n[a] > n[longest]) longest = a;
  auto side = [&](int a) { return (grid.bounds.hi[a] - grid.bounds.lo[a]) / double(n[a]); };
  layout.voxelSide = side(longest);
  layout.translate = grid.bounds.lo;
  layout.scale = layout.voxelSide * double(layout.dim);
  for (int a = 0; a < 3; ++a)
    layout.farFaceShiftVoxels =
        std::max(layout.farFaceShiftVoxels, double(n[a]) * std::fabs(side(a) - layout.voxelSide) / layout.voxelSide);
  return layout;
}

BinvoxLayout writeBinvox(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress) {
  binvoxLayout(grid);  // a cube too large is refused before anything else
  tallyVoxels(grid);   // and keys or runs that break the grid's rules before a row is visited
  if (progress) progress(0);
  return writeBinvox(out, grid, voxelRows(grid), progress);
}

BinvoxLayout writeBinvox(std::ostream& out, const Grid& plan, const VoxelRowSource& forEachRow,
                         const std::function<void(double)>& progress) {
  const BinvoxLayout layout = binvoxLayout(plan);
  const uint64_t d = layout.dim;
  const uint64_t planeBits = d * d;
  // Toggle events bucketed by the plane x where they happen (x = D: past the last plane, dropped). Counted in one
  // pass over the rows (the counts are D + 2 numbers), checked against the budget before the events are allocated.
  std::vector<uint64_t> eventStart(d + 2, 0);
  forEachRow([&](const VoxelRow& r) {
    ++eventStart[r.i0 + 1];
    ++eventStart[r.i0 + r.count + 1];
  });
  for (size_t x = 1; x < eventStart.size(); ++x) eventStart[x] += eventStart[x - 1];
  // Each serial pass over the rows takes tenths of a second at 2048^3: the progress callback (which throws to
  // cancel) is asked between them and after every plane.
  if (progress) progress(0);
  requireMemory(saturatingSum({saturatingMul(eventStart.back(), sizeof(uint32_t)), (d + 1) * sizeof(uint64_t),
                               planeBits / 8 + planeBits / 64 * 5}),
                "binvox", "run events and one plane (with its words' marks and list)");
  std::vector<uint32_t> events(eventStart.back());
  {
    std::vector<uint64_t> fill(eventStart.begin(), eventStart.end() - 1);
    forEachRow([&](const VoxelRow& r) {
      const uint32_t bit = uint32_t(uint64_t(r.k) * d + r.j);  // D <= 4096, so D*D < 2^32
      events[fill[r.i0]++] = bit;
      events[fill[r.i0 + r.count]++] = bit;
    });
  }
  if (progress) progress(0);

  char header[256];
  std::snprintf(header, sizeof header, "#binvox 1\ndim %u %u %u\ntranslate %.17g %.17g %.17g\nscale %.17g\ndata\n",
                layout.dim, layout.dim, layout.dim, layout.translate.x, layout.translate.y, layout.translate.z,
                layout.scale);
  out << header;
  RunEncoder enc(out);
  // The plane words any event sets (bits j + D k of the rows that hold voxels), ascending.
  std::vector<uint64_t> plane((planeBits + 63) / 64, 0);
  std::vector<uint32_t> active;
  {
    std::vector<uint8_t> marked(plane.size(), 0);  // D^2 / 64 bytes, a quarter of the plane
    for (const uint32_t bit : events) marked[bit / 64] = 1;
    for (uint32_t w = 0; w < marked.size(); ++w)
      if (marked[w]) active.push_back(w);
  }
  if (progress) progress(0);
  uint64_t setBits = 0;
  for (uint64_t x = 0; x < d; ++x) {
    for (uint64_t e = eventStart[x]; e < eventStart[x + 1]; ++e) {
      uint64_t& word = plane[events[e] / 64];
      const uint64_t bit = uint64_t(1) << (events[e] % 64);
      word ^= bit;
      setBits = word & bit ? setBits + 1 : setBits - 1;
    }
    encodePlane(plane, planeBits, setBits, active, enc);
    if (progress) progress(double(x) / double(d));
  }
  enc.finish();
  return layout;
}

}  // namespace vox
