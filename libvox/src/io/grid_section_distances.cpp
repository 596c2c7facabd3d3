// The Distances section of grid files (docs/grid-format.md "Sections"): the narrow band of --sdf, written only for a
// grid that has one.
//
// Body: f64 half-width (smallest cell edges), u64 B, B u64 cell keys (strictly ascending, inside the grid), B f64
// signed distances (finite). Keys sorted and unique, so a file has one encoding.
#include <string>

#include "io/grid_sections.h"
#include "vox/core/exact_number.h"

namespace vox {

bool hasDistancesSection(const Scene&, const Grid& grid) { return grid.sdfHalfWidth > 0; }

void putDistancesSection(ByteWriter& w, const Scene&, const Grid& grid) {
  w.put(grid.sdfHalfWidth);
  w.putArray(grid.sdfKeys);
  w.putBytes({reinterpret_cast<const char*>(grid.sdfValues.data()), grid.sdfValues.size() * sizeof(double)});
}

void getDistancesSection(ByteReader& r, Scene&, Grid& grid) {
  const double halfWidth = r.getFinite("distance band half-width");
  // 64: kMaxSdfHalfWidth (vox/distance/sdf.h), the widest band the writers make.
  if (!(halfWidth > 0) || halfWidth > 64)
    r.corrupt("distance band half-width " + exactNumber(halfWidth) + " outside (0, 64] cell edges");
  std::vector<uint64_t> keys = r.getArray<uint64_t>("distance band cell");
  r.need(keys.size() * sizeof(double));
  for (size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] >= grid.cellCount()) r.corrupt("distance band cell " + std::to_string(keys[i]) + " outside the grid");
    if (i > 0 && keys[i] <= keys[i - 1]) r.corrupt("distance band cells not strictly ascending");
  }
  std::vector<double> values(keys.size());
  for (double& v : values) v = r.getFinite("signed distance");
  grid.sdfHalfWidth = halfWidth;
  grid.sdfKeys = std::move(keys);
  grid.sdfValues = std::move(values);
}

}  // namespace vox
