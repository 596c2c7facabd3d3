// A running sum of doubles whose rounding error does not grow with the number of terms: Neumaier's improvement of
// Kahan summation (Z. angew. Math. Mech. 54, 1974). Totals that are compared with an exact value (a mesh's volume
// against the sum of millions of equal cell volumes) need it: plain summation of n equal terms drifts by up to
// n eps / 2 of the total, 1e-10 at a few million cells.
#pragma once

#include <cmath>

namespace vox {

struct CompensatedSum {
  double sum = 0;
  double correction = 0;  // the low-order parts the additions to `sum` rounded away

  void add(double x) {
    const double t = sum + x;
    correction += std::fabs(sum) >= std::fabs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
  }
  double value() const { return sum + correction; }
};

}  // namespace vox
