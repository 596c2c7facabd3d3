#include "vox/voxelize/fill.h"

#include <bit>
#include <vector>

#include "vox/core/error.h"

namespace vox {

namespace {

// A dense bit per cell: 2048^3 cells take 1 GiB, still far below a dense array of anything larger.
class CellBits {
 public:
  explicit CellBits(uint64_t cells) : words_((cells + 63) / 64, 0) {}
  bool get(uint64_t key) const { return (words_[key >> 6] >> (key & 63)) & 1; }
  void set(uint64_t key) { words_[key >> 6] |= uint64_t(1) << (key & 63); }
  size_t wordCount() const { return words_.size(); }
  uint64_t word(size_t w) const { return words_[w]; }

 private:
  std::vector<uint64_t> words_;
};

}  // namespace

// Scanline flood fill from every empty boundary cell: a seed grows into the maximal run of free cells along x,
// and the four neighbouring rows of that run seed further runs. The stack holds runs, not cells, so it stays
// proportional to the surface rather than the volume.
void fillSolid(Grid& grid, uint64_t memoryLimitBytes) {
  const auto d = grid.dims;
  const uint64_t cells = grid.cellCount();
  if (cells / 8 > memoryLimitBytes)
    fail<LimitError>("solid fill of a ", d[0], "x", d[1], "x", d[2], " grid needs ", cells / 8 / (1 << 20),
                     " MiB of scratch memory, more than the ", memoryLimitBytes >> 20, " MiB allowed");
  CellBits blocked(cells);  // occupied or already reached from outside
  for (uint64_t key : grid.cellKeys) blocked.set(key);

  struct Seed {
    uint32_t i, j, k;
  };
  std::vector<Seed> stack;
  auto push = [&](int64_t i, int64_t j, int64_t k) {
    if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2]) return;
    if (!blocked.get(cellKey(d, i, j, k))) stack.push_back({uint32_t(i), uint32_t(j), uint32_t(k)});
  };
  auto flood = [&] {
    while (!stack.empty()) {
      const Seed s = stack.back();
      stack.pop_back();
      const uint64_t row = cellKey(d, 0, s.j, s.k);
      if (blocked.get(row + s.i)) continue;
      int64_t lo = s.i, hi = s.i;
      while (lo > 0 && !blocked.get(row + lo - 1)) --lo;
      while (hi + 1 < d[0] && !blocked.get(row + hi + 1)) ++hi;
      for (int64_t i = lo; i <= hi; ++i) blocked.set(row + i);
      // One seed per maximal free run in each neighbouring row.
      const int64_t nj[4] = {int64_t(s.j) - 1, int64_t(s.j) + 1, s.j, s.j};
      const int64_t nk[4] = {s.k, s.k, int64_t(s.k) - 1, int64_t(s.k) + 1};
      for (int n = 0; n < 4; ++n) {
        if (nj[n] < 0 || nk[n] < 0 || nj[n] >= d[1] || nk[n] >= d[2]) continue;
        const uint64_t nrow = cellKey(d, 0, nj[n], nk[n]);
        bool inRun = false;
        for (int64_t i = lo; i <= hi; ++i) {
          const bool free = !blocked.get(nrow + i);
          if (free && !inRun) stack.push_back({uint32_t(i), uint32_t(nj[n]), uint32_t(nk[n])});
          inRun = free;
        }
      }
    }
  };
  // Seeds: every cell on the six faces of the grid.
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j) {
      const bool edgeRow = j == 0 || k == 0 || j == d[1] - 1 || k == d[2] - 1;
      if (edgeRow) {
        for (int64_t i = 0; i < d[0]; ++i) push(i, j, k);
      } else {
        push(0, j, k);
        push(d[0] - 1, j, k);
      }
      flood();
    }
  // Runs are appended as the free bits are met in key order; a run costs 16 bytes, at most one per two cells.
  grid.solidRuns.clear();
  for (uint64_t w = 0; w < blocked.wordCount(); ++w) {
    uint64_t free = ~blocked.word(w);
    while (free) {
      const uint64_t key = w * 64 + uint64_t(std::countr_zero(free));
      if (key >= cells) break;
      appendSolidKey(grid.solidRuns, key);
      free &= free - 1;
    }
  }
}

}  // namespace vox
