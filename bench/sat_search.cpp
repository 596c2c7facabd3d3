// Does the floating-point `sat` test ever miss a cell that the exact test takes? Searches adversarial
// triangle-cell pairs (tests/adversary.h: boundary contacts, cell planes, degenerate and tiny triangles, scales
// 1e-6 to 1e6, offsets to 1e7) and reports misses and false hits per case, with the smallest miss found.
// Usage: sat_search [PAIRS_PER_CASE]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "adversary.h"
#include "vox/voxelize/overlap.h"

int main(int argc, char** argv) {
  using namespace vox;
  if (argc > 1 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))) {
    std::printf(
        "sat_search [PAIRS_PER_CASE]\n  Searches adversarial triangle-cell pairs for cells the sat test misses or "
        "adds against the exact test (default 200000 pairs a case).\n");
    return 0;
  }
  const long pairs = argc > 1 ? std::atol(argv[1]) : 200000;
  if (pairs <= 0) {
    std::fprintf(stderr, "sat_search: PAIRS_PER_CASE must be a positive number, not %s\n", argv[1]);
    return 1;
  }
  bool found = false;
  Triangle best;
  Box bestBox;
  double bestSize = HUGE_VAL;
  std::printf("%-8s %-8s %10s %10s %10s %10s\n", "scale", "offset", "pairs", "exact_hits", "sat_missed", "sat_added");
  for (const auto& c : testing::kCases) {
    testing::Adversary adv(2024, c);
    long hits = 0, missed = 0, added = 0;
    for (long n = 0; n < pairs; ++n) {
      const Triangle t = adv.triangle();
      const Box box = adv.cell();
      const bool exact = triangleBoxExact(t, box);
      const bool sat = triangleBoxSat(t, box);
      hits += exact;
      if (exact && !sat) {
        ++missed;
        // "Smallest": the miss whose coordinates have the smallest magnitude, so it reads most simply.
        double size = 0;
        for (const auto& v : t.v) size = std::max({size, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
        if (size < bestSize) {
          bestSize = size;
          best = t;
          bestBox = box;
          found = true;
        }
      }
      added += sat && !exact;
    }
    std::printf("%-8g %-8g %10ld %10ld %10ld %10ld\n", c.scale, c.offset, pairs, hits, missed, added);
  }
  if (found) {
    std::printf("smallest miss: triangle");
    for (const auto& v : best.v) std::printf(" (%.17g, %.17g, %.17g)", v.x, v.y, v.z);
    std::printf("\n  cell (%.17g, %.17g, %.17g) - (%.17g, %.17g, %.17g): exact says they meet, sat says not\n",
                bestBox.lo.x, bestBox.lo.y, bestBox.lo.z, bestBox.hi.x, bestBox.hi.y, bestBox.hi.z);
  } else {
    std::printf("sat missed no cell\n");
  }
  return 0;
}
