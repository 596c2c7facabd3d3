#include "volume/ball_box.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace vox::volume {

namespace {

// x - sin x without the cancellation of the direct form at small x (Taylor series, remainder below 1e-17 relative).
double xMinusSin(double x) {
  if (x >= 0.25) return x - std::sin(x);
  const double x2 = x * x;
  return x * x2 * (1.0 / 6 - x2 * (1.0 / 120 - x2 * (1.0 / 5040 - x2 * (1.0 / 362880 - x2 / 39916800))));
}

double halfChord(double rho, double u) { return std::sqrt(std::max(0.0, (rho - u) * (rho + u))); }

// The integral of sqrt(rho^2 - u^2) over [p, q]: the trapezoid under the chord plus the circular segment between
// chord and arc, both non-negative, so nothing cancels. The segment's angle by atan2, well conditioned everywhere.
double arcIntegral(double rho, double p, double q) {
  const double sp = halfChord(rho, p), sq = halfChord(rho, q);
  const double theta = std::atan2(std::fabs(p * sq - q * sp), p * q + sp * sq);
  return 0.5 * (q - p) * (sp + sq) + 0.5 * rho * rho * xMinusSin(theta);
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from Chebyshev guesses; Numerical Recipes 4.6).
struct GaussRule {
  std::vector<double> x, w;
  explicit GaussRule(int n) : x(n), w(n) {
    for (int i = 0; i < n; ++i) {
      double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 1;
      for (int it = 0; it < 100; ++it) {
        double p1 = 1, p2 = 0;
        for (int j = 1; j <= n; ++j) {
          const double p3 = p2;
          p2 = p1;
          p1 = ((2.0 * j - 1) * z * p2 - (j - 1.0) * p3) / j;
        }
        dp = n * (z * p1 - p2) / (z * z - 1);
        const double step = p1 / dp;
        z -= step;
        if (std::fabs(step) < 1e-16) break;
      }
      x[i] = z;
      w[i] = 2 / ((1 - z * z) * dp * dp);
    }
  }
};

struct BallBoxSection {
  double r;
  Vec3 lo, hi;  // the box relative to the ball's centre
  double area(double z) const { return diskRectArea(halfChord(r, z), lo.x, hi.x, lo.y, hi.y); }
};

// The integral of the section's area over [a, b], after z = a + (b - a)(1 - cos t)/2 (t in [0, pi]), which turns
// the (z - a)^(1/2) and (b - z)^(1/2) behaviour at the ends of a piece into smooth functions of t.
double gaussPiece(const BallBoxSection& s, double a, double b, const GaussRule& rule) {
  double sum = 0;
  for (size_t i = 0; i < rule.x.size(); ++i) {
    const double t = 0.5 * std::numbers::pi * (1 + rule.x[i]);
    sum += rule.w[i] * s.area(a + 0.5 * (b - a) * (1 - std::cos(t))) * std::sin(t);
  }
  return sum * 0.25 * std::numbers::pi * (b - a);
}

// The Gauss rules' agreement asked of a piece, relative to the cell's volume. The section's area is computed at the
// ball's scale and loses about two digits where the cell is small against the ball (an arc's integral minus a
// rectangle's), so differences below about 1e-14 of the cell are rounding, not quadrature error: a tolerance there
// never converges and the bisection runs to its depth limit (14.8 s for a ball at 128^3 with 1e-15 and depth 30;
// docs/distance.md). 1e-13 stays ten times below the 1e-12 the fractions promise.
constexpr double kPieceTolerance = 1e-13;
constexpr int kMaxDepth = 16;

double adaptivePiece(const BallBoxSection& s, double a, double b, double tolerance, int depth) {
  static const GaussRule coarse(20), fine(40);
  const double i1 = gaussPiece(s, a, b, coarse), i2 = gaussPiece(s, a, b, fine);
  if (std::fabs(i1 - i2) <= tolerance || depth == 0) return i2;
  const double m = 0.5 * (a + b);
  return adaptivePiece(s, a, m, 0.5 * tolerance, depth - 1) + adaptivePiece(s, m, b, 0.5 * tolerance, depth - 1);
}

}  // namespace

double diskRectArea(double rho, double u0, double u1, double v0, double v1) {
  const double a = std::max(u0, -rho), b = std::min(u1, rho);
  if (!(rho > 0) || !(a < b) || !(v0 < v1)) return 0;
  // Where the disk's circle meets the lines v = v0 and v = v1 the integrand changes form.
  std::array<double, 6> cuts{};
  int n = 0;
  cuts[n++] = a;
  for (const double v : {v0, v1})
    if (std::fabs(v) <= rho)
      for (const double u : {-halfChord(rho, v), halfChord(rho, v)})
        if (u > a && u < b) cuts[n++] = u;
  cuts[n++] = b;
  // Insertion sort of at most 6: std::sort's unrolled insertion step trips GCC 12's -Warray-bounds here.
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && cuts[j] < cuts[j - 1]; --j) std::swap(cuts[j], cuts[j - 1]);
  double area = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const double p = cuts[i], q = cuts[i + 1];
    if (!(p < q)) continue;
    const double s = halfChord(rho, 0.5 * (p + q));
    const bool upperArc = s<v1, lowerArc = -s> v0;
    if ((upperArc ? s : v1) <= (lowerArc ? -s : v0)) continue;  // the column misses the disk on this piece
    const double arc = (upperArc || lowerArc) ? arcIntegral(rho, p, q) : 0;
    area += (upperArc ? arc : v1 * (q - p)) - (lowerArc ? -arc : v0 * (q - p));
  }
  return area;
}

double ballBoxVolume(const Vec3& center, double radius, const Box& box) {
  const BallBoxSection s{radius, box.lo - center, box.hi - center};
  const double za = std::max(s.lo.z, -radius), zb = std::min(s.hi.z, radius);
  if (!(za < zb)) return 0;
  // Heights where the section's circle passes a corner of the rectangle or touches one of its side lines.
  std::vector<double> cuts{za, zb};
  const double xs[2] = {s.lo.x, s.hi.x}, ys[2] = {s.lo.y, s.hi.y};
  std::vector<double> d2;
  for (const double x : xs) d2.push_back(x * x);
  for (const double y : ys) d2.push_back(y * y);
  for (const double x : xs)
    for (const double y : ys) d2.push_back(x * x + y * y);
  for (const double d : d2)
    if (d < radius * radius) {
      const double z = std::sqrt(radius * radius - d);
      for (const double c : {-z, z})
        if (c > za && c < zb) cuts.push_back(c);
    }
  std::sort(cuts.begin(), cuts.end());
  const double boxVolume = (box.hi.x - box.lo.x) * (box.hi.y - box.lo.y) * (box.hi.z - box.lo.z);
  double volume = 0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i)
    if (cuts[i] < cuts[i + 1]) volume += adaptivePiece(s, cuts[i], cuts[i + 1], kPieceTolerance * boxVolume, kMaxDepth);
  return volume;
}

}  // namespace vox::volume
