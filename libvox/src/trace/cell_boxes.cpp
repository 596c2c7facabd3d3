// Accel::cellBoxes (issue 27): for each empty or solid cell of the block tables, a box of cells around it that holds
// no primitive, so that a walk entering the cell jumps to the box's exit instead of stepping through its cells one
// by one (the merged empty cells of the irregular grid of Pérard-Gayot, Kalojanov and Slusallek, 2017, kept as one
// box per cell instead of a merged cell list, so that the walk stays the uniform walk between jumps).
//
// Whether a layer of cells holds a primitive is answered in O(1) by a summed-volume table of the occupied cells, so
// growing a box costs a few lookups per face; reaches are capped (kBoxReachCap) to bound the build on grids with
// wide empty spaces, which the block-level skipping (Accel::emptyShift) already crosses.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "vox/trace/accel.h"

namespace vox {
namespace {

constexpr uint32_t kBoxReachCap = 16;
static_assert(kBoxReachCap <= kMaxBoxReach);

// Counts of occupied cells over boxes of the grid: sum[(x, y, z)] is the number of occupied cells with indices below
// (x, y, z) on every axis; a box's count is the usual inclusion-exclusion of eight entries.
class OccupiedCounts {
 public:
  explicit OccupiedCounts(const Accel& accel) : n_(accel.grid->dims) {
    sum_.assign(size_t(n_[0] + 1) * (n_[1] + 1) * (n_[2] + 1), 0);
    for (uint32_t z = 0; z < n_[2]; ++z)
      for (uint32_t y = 0; y < n_[1]; ++y)
        for (uint32_t x = 0; x < n_[0]; ++x) {
          const bool occupied = !accel.blockEmpty(x, y, z) && accel.lookup(x, y, z) < kSolidCell;
          at(x + 1, y + 1, z + 1) = uint32_t(occupied) + at(x, y + 1, z + 1) + at(x + 1, y, z + 1) +
                                    at(x + 1, y + 1, z) - at(x, y, z + 1) - at(x, y + 1, z) - at(x + 1, y, z) +
                                    at(x, y, z);
        }
  }
  // Occupied cells in the box [lo, hi] (inclusive indices, inside the grid).
  uint32_t box(const std::array<uint32_t, 3>& lo, const std::array<uint32_t, 3>& hi) const {
    const uint32_t x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0] + 1, y1 = hi[1] + 1, z1 = hi[2] + 1;
    return at(x1, y1, z1) - at(x0, y1, z1) - at(x1, y0, z1) - at(x1, y1, z0) + at(x0, y0, z1) + at(x0, y1, z0) +
           at(x1, y0, z0) - at(x0, y0, z0);
  }

 private:
  uint32_t& at(uint32_t x, uint32_t y, uint32_t z) { return sum_[x + size_t(n_[0] + 1) * (y + size_t(n_[1] + 1) * z)]; }
  uint32_t at(uint32_t x, uint32_t y, uint32_t z) const {
    return sum_[x + size_t(n_[0] + 1) * (y + size_t(n_[1] + 1) * z)];
  }
  std::array<uint32_t, 3> n_;
  std::vector<uint32_t> sum_;
};

// The box grown around the empty cell c: each face in turn (x-, x+, y-, y+, z-, z+) takes one more layer when the
// layer lies in the grid, holds no occupied cell and the reach stays under the cap, until no face can grow.
CellBox growEmptyBox(const OccupiedCounts& counts, const std::array<uint32_t, 3>& dims,
                     const std::array<uint32_t, 3>& c) {
  std::array<uint32_t, 3> lo = c, hi = c;
  for (bool grew = true; grew;) {
    grew = false;
    for (int face = 0; face < 6; ++face) {
      const int a = face / 2;
      const bool up = face % 2 == 1;
      if (up ? (hi[a] + 1 >= dims[a] || hi[a] - c[a] >= kBoxReachCap) : (lo[a] == 0 || c[a] - lo[a] >= kBoxReachCap))
        continue;
      std::array<uint32_t, 3> layerLo = lo, layerHi = hi;
      layerLo[a] = layerHi[a] = up ? hi[a] + 1 : lo[a] - 1;
      if (counts.box(layerLo, layerHi) != 0) continue;
      (up ? hi[a] : lo[a]) = layerLo[a];
      grew = true;
    }
  }
  CellBox box;
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = uint8_t(c[a] - lo[a]);
    box.hi[a] = uint8_t(hi[a] - c[a]);
  }
  return box;
}

}  // namespace

void buildCellBoxes(Accel& accel) {
  accel.cellBoxes.clear();
  const std::array<uint32_t, 3> dims = accel.grid->dims;
  if (accel.blockShift == 0 || accel.grid->cellCount() > kMaxBoxGridCells) return;
  const OccupiedCounts counts(accel);
  accel.cellBoxes.assign(accel.cellSlots.size(), CellBox{{0, 0, 0}, {0, 0, 0}});
  const uint32_t s = accel.blockShift, side = 1u << s, m = side - 1;
  const auto& bd = accel.blockDims;
  // Each block's cells get their boxes independently (the counts are only read): blocks in parallel.
  tbb::parallel_for(uint32_t(0), bd[2], [&](uint32_t bz) {
    for (uint32_t by = 0; by < bd[1]; ++by)
      for (uint32_t bx = 0; bx < bd[0]; ++bx) {
        const uint32_t b = accel.blockSlot[bx + bd[0] * (by + uint64_t(bd[1]) * bz)];
        if (b == kEmptyCell) continue;
        for (uint32_t local = 0; local < (1u << (3 * s)); ++local) {
          const std::array<uint32_t, 3> c{(bx << s) | (local & m), (by << s) | ((local >> s) & m),
                                          (bz << s) | ((local >> (2 * s)) & m)};
          if (c[0] >= dims[0] || c[1] >= dims[1] || c[2] >= dims[2]) continue;
          const uint64_t slot = (uint64_t(b) << (3 * s)) + local;
          if (accel.cellSlots[slot] < kSolidCell) continue;  // occupied: tested where it is
          accel.cellBoxes[slot] = growEmptyBox(counts, dims, c);
        }
      }
  });
}

}  // namespace vox
