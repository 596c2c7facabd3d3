// Growing a large array without a long silent stretch: resizing zero-fills (or value-fills) fresh pages on the
// calling thread alone, 0.1 to 3.4 s for the largest arrays of a 2048^3 fill or a 512^3 voxel mesh on a busy
// machine, longer than Ctrl-C may wait. The fill, the importers and the voxel mesh grow their arrays with it.
#pragma once

#include <algorithm>
#include <cstddef>

namespace vox {

// v.resize(n, value) in steps of 8 MiB, calling between() after each step (it may throw to cancel). Values as
// resize gives; when n is below v.size(), v shrinks to n.
template <typename Vector, typename Between>
void resizeInSteps(Vector& v, size_t n, const typename Vector::value_type& value, const Between& between) {
  const size_t step = std::max<size_t>(1, (size_t{8} << 20) / sizeof(typename Vector::value_type));
  v.reserve(n);
  while (v.size() < n) {
    v.resize(std::min(n, v.size() + step), value);
    between();
  }
  v.resize(n, value);
}

}  // namespace vox
