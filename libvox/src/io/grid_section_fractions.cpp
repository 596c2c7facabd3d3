// The Fractions section of grid files (docs/grid-format.md "Sections"): the volume fractions of --fraction, one per
// occupied cell in the order of the cell keys, written only for a grid that has them.
//
// Body: u64 N (the occupied cell count), N f64 fractions, each in [0, 1].
#include <string>

#include "io/grid_sections.h"
#include "vox/core/exact_number.h"

namespace vox {

bool hasFractionsSection(const Scene&, const Grid& grid) { return !grid.fractions.empty(); }

void putFractionsSection(ByteWriter& w, const Scene&, const Grid& grid, std::string&) { w.putArray(grid.fractions); }

void getFractionsSection(ByteReader& r, Scene&, Grid& grid, const SectionContext&) {
  std::vector<double> fractions = r.getArray<double>("volume fraction");
  if (fractions.size() != grid.occupiedCount())
    r.corrupt(std::to_string(fractions.size()) + " volume fractions for " + std::to_string(grid.occupiedCount()) +
              " occupied cells");
  for (double f : fractions)
    if (!(f >= 0 && f <= 1)) r.corrupt("volume fraction " + exactNumber(f) + " outside [0, 1]");
  grid.fractions = std::move(fractions);
}

}  // namespace vox
