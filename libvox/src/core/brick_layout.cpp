#include "vox/core/brick_layout.h"

#include <algorithm>
#include <map>

#include "vox/core/error.h"

namespace vox {

namespace {

// A set lists its bricks and a tool keeps one candidate list per brick: beyond this many bricks that bookkeeping,
// not the cells, would dominate memory.
constexpr uint64_t kMaxBricks = uint64_t(1) << 24;

}  // namespace

void checkBrickCounts(const std::array<uint32_t, 3>& dims, const std::array<uint32_t, 3>& bricks) {
  for (int a = 0; a < 3; ++a)
    if (bricks[a] == 0 || bricks[a] > dims[a])
      fail<UsageError>("--bricks: ", bricks[a], " bricks on axis ", "xyz"[a], " of a grid ", dims[0], "x", dims[1], "x",
                       dims[2], " (each brick needs at least one cell: 1 to ", dims[a], ")");
  if (uint64_t(bricks[0]) * bricks[1] * bricks[2] > kMaxBricks)
    fail<UsageError>("--bricks: ", bricks[0], "x", bricks[1], "x", bricks[2], " bricks, more than the ", kMaxBricks,
                     " allowed");
}

CellWindow brickWindow(const std::array<uint32_t, 3>& dims, const std::array<uint32_t, 3>& bricks,
                       const std::array<uint32_t, 3>& index) {
  CellWindow w;
  for (int a = 0; a < 3; ++a) {
    VOX_CHECK(index[a] < bricks[a] && bricks[a] <= dims[a]);
    w.first[a] = uint32_t(uint64_t(dims[a]) * index[a] / bricks[a]);
    w.end[a] = uint32_t(uint64_t(dims[a]) * (index[a] + 1) / bricks[a]);
  }
  return w;
}

uint64_t brickNumber(const std::array<uint32_t, 3>& bricks, const std::array<uint32_t, 3>& index) {
  return index[0] + uint64_t(bricks[0]) * (index[1] + uint64_t(bricks[1]) * index[2]);
}

std::array<uint32_t, 3> brickIndex(const std::array<uint32_t, 3>& bricks, uint64_t number) {
  return {uint32_t(number % bricks[0]), uint32_t(number / bricks[0] % bricks[1]),
          uint32_t(number / (uint64_t(bricks[0]) * bricks[1]))};
}

void appendSolidRun(std::vector<CellRun>& runs, const CellRun& run) {
  if (!runs.empty() && runs.back().first + runs.back().count == run.first)
    runs.back().count += run.count;
  else
    runs.push_back(run);
}

std::vector<std::pair<uint64_t, std::vector<CellRun>>> splitRunsByBrick(std::span<const CellRun> runs,
                                                                        const std::array<uint32_t, 3>& dims,
                                                                        const std::array<uint32_t, 3>& bricks) {
  checkBrickCounts(dims, bricks);
  const uint64_t nx = dims[0], ny = dims[1];
  std::map<uint64_t, std::vector<CellRun>> byBrick;
  for (const CellRun& run : runs) {
    // A run may cross row ends (a row's last empty run and the next row's first): cut it into rows, then each
    // row piece at the bricks' x boundaries.
    for (uint64_t key = run.first, end = run.first + run.count; key < end;) {
      const uint64_t row = key / nx, x0 = key % nx, x1 = std::min(nx, x0 + (end - key));
      const uint32_t by = brickOfCell(row % ny, ny, bricks[1]), bz = brickOfCell(row / ny, dims[2], bricks[2]);
      for (uint32_t bx = brickOfCell(x0, nx, bricks[0]); bx < bricks[0]; ++bx) {
        const uint64_t lo = std::max(x0, nx * bx / bricks[0]), hi = std::min(x1, nx * (bx + 1) / bricks[0]);
        if (lo >= hi) break;
        appendSolidRun(byBrick[brickNumber(bricks, {bx, by, bz})], {row * nx + lo, hi - lo});
      }
      key = row * nx + x1;
    }
  }
  return {std::make_move_iterator(byBrick.begin()), std::make_move_iterator(byBrick.end())};
}

}  // namespace vox
