// The `sat` method: Akenine-Moller's separating-axis triangle-box test ("Fast 3D Triangle-Box Overlap Testing",
// JGT 2001) in double precision, without an exact fallback.
#include <algorithm>
#include <cmath>

#include "voxelize/triangle_filter.h"
#include "vox/voxelize/overlap.h"

namespace vox {

// The 13 axes evaluated in double relative to the triangle's first vertex (face axes compared exactly), with the
// filter's rigorous rounding bounds: an axis separates only when it certainly does. So `sat` never misses a cell;
// where rounding leaves a contact undecided it takes the cell (a hair too many), which keeps grid traversal
// identical to brute force. Akenine-Moller's published form translates to the box centre first; its rounding
// there drops triangles lying in a cell's face plane (found on scene5_11, whose triangles lie on the grid's face).
bool triangleBoxSat(const Triangle& t, const Box& box) {
  TriangleFilter filter(t);
  return filter.test(box) != FilterResult::Disjoint;
}

}  // namespace vox
