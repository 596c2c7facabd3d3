#include "voxelize/triangle_filter.h"
#include "vox/voxelize/overlap.h"

namespace vox {

bool triangleBoxFiltered(const Triangle& t, const Box& box, bool* usedFallback) {
  TriangleFilter filter(t);
  const FilterResult r = filter.test(box);
  if (usedFallback) *usedFallback = r == FilterResult::Unknown;
  if (r == FilterResult::Unknown) return triangleBoxExact(t, box);
  return r == FilterResult::Overlap;
}

}  // namespace vox
