// Accel::cellBoxes (issue 27): for each cell of the block tables, a box of cells around it each of which holds only
// primitives the cell itself holds, so that a walk that has tested the cell jumps to the box's exit instead of
// stepping through its cells one by one. For an empty or solid cell that is a box of empty space (the merged empty
// cells of the irregular grid of Pérard-Gayot, Kalojanov and Slusallek, 2017); for an occupied cell it is their
// expansion over neighbours whose lists are subsets of its own. Kept as one box per cell instead of a merged cell
// list, so that the walk stays the uniform walk between jumps.
//
// Whether a layer of cells holds a primitive is answered in O(1) by a summed-volume table of the occupied cells, so
// growing a box through empty space costs a few lookups per face; a layer with occupied cells is checked cell by cell
// (only for an occupied cell's box). Reaches are capped (kBoxReachCap) to bound the build on grids with wide empty
// spaces, which the block-level skipping (Accel::emptyShift) already crosses.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
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

// Does every occupied cell of the box [lo, hi] hold only primitives of `own` (ascending)? The layer's cells are
// looked up one by one; an empty `own` (an empty or solid cell's box) admits no occupied cell.
bool layerWithin(const Accel& accel, const OccupiedCounts& counts, const std::array<uint32_t, 3>& lo,
                 const std::array<uint32_t, 3>& hi, std::span<const uint32_t> own) {
  if (counts.box(lo, hi) == 0) return true;
  if (own.empty()) return false;
  for (uint32_t z = lo[2]; z <= hi[2]; ++z)
    for (uint32_t y = lo[1]; y <= hi[1]; ++y)
      for (uint32_t x = lo[0]; x <= hi[0]; ++x) {
        const uint32_t c = accel.lookup(x, y, z);
        if (c >= kSolidCell) continue;
        const std::span<const uint32_t> prims = accel.cellPrims(c);
        if (prims.size() > own.size()) return false;
        for (const uint32_t id : prims)
          if (!std::binary_search(own.begin(), own.end(), id)) return false;
      }
  return true;
}

// The box grown around cell c, whose primitives are `own` (ascending; empty for an empty or solid cell): each face
// in turn (x-, x+, y-, y+, z-, z+) takes one more layer when the layer lies in the grid, holds only cells whose
// primitives are all in `own` and the reach stays under the cap, until no face can grow.
CellBox growBox(const Accel& accel, const OccupiedCounts& counts, const std::array<uint32_t, 3>& c,
                std::span<const uint32_t> own) {
  const std::array<uint32_t, 3> dims = accel.grid->dims;
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
      if (!layerWithin(accel, counts, layerLo, layerHi, own)) continue;
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
  std::vector<uint32_t> own;
  for (uint32_t bz = 0; bz < bd[2]; ++bz)
    for (uint32_t by = 0; by < bd[1]; ++by)
      for (uint32_t bx = 0; bx < bd[0]; ++bx) {
        const uint32_t b = accel.blockSlot[bx + bd[0] * (by + uint64_t(bd[1]) * bz)];
        if (b == kEmptyCell) continue;
        for (uint32_t local = 0; local < (1u << (3 * s)); ++local) {
          const std::array<uint32_t, 3> c{(bx << s) | (local & m), (by << s) | ((local >> s) & m),
                                          (bz << s) | ((local >> (2 * s)) & m)};
          if (c[0] >= dims[0] || c[1] >= dims[1] || c[2] >= dims[2]) continue;
          const uint64_t slot = (uint64_t(b) << (3 * s)) + local;
          const uint32_t cell = accel.cellSlots[slot];
          if (cell < kSolidCell) {
            // The cell's own list, ascending (grid files are checked for it; sorted again so that a grid built
            // otherwise cannot make a box hold a primitive the cell lacks).
            const std::span<const uint32_t> prims = accel.cellPrims(cell);
            own.assign(prims.begin(), prims.end());
            std::sort(own.begin(), own.end());
            accel.cellBoxes[slot] = growBox(accel, counts, c, own);
          } else {
            accel.cellBoxes[slot] = growBox(accel, counts, c, {});
          }
        }
      }
}

}  // namespace vox
