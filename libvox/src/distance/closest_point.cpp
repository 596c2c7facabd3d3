#include "vox/distance/closest_point.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "vox/core/error.h"

namespace vox {

Vec3 closestPointOnSegment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 ab = b - a;
  const double len2 = dot(ab, ab);
  if (!(len2 > 0)) return a;
  const double t = std::clamp(dot(p - a, ab) / len2, 0.0, 1.0);
  return t == 1 ? b : a + ab * t;
}

namespace {

// The point of triangle (a, b, c) nearest to the origin. The nearest of the three edges, and the projection onto the
// plane when it falls inside: a misjudged region test near an edge then costs a hair of distance, never a wrong
// region's point (Ericson's single-region formula loses digits on needle triangles, whose sub-areas cancel).
Vec3 closestToOrigin(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 o{0, 0, 0};
  Vec3 best = closestPointOnSegment(a, b, o);
  double bestD2 = dot(best, best);
  for (const auto& [s, t] : {std::pair{b, c}, std::pair{c, a}}) {
    const Vec3 q = closestPointOnSegment(s, t, o);
    const double d2 = dot(q, q);
    if (d2 < bestD2) best = q, bestD2 = d2;
  }
  const Vec3 n = cross(b - a, c - a);
  const double nn = dot(n, n);
  if (nn > 0 && dot(cross(b - a, -a), n) >= 0 && dot(cross(c - b, -b), n) >= 0 && dot(cross(a - c, -c), n) >= 0) {
    const Vec3 q = n * (dot(n, a) / nn);
    if (dot(q, q) < bestD2) best = q;
  }
  return best;
}

}  // namespace

// Both work relative to p: the differences a - p are exact or nearly so, and every later rounding is relative to the
// triangle's size and distance instead of to the coordinates' magnitude (a scene 1e6 from the origin with 1e-6 cells).
Vec3 closestPointOnTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  return p + closestToOrigin(a - p, b - p, c - p);
}

double squaredDistanceToTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const Vec3 q = closestToOrigin(a - p, b - p, c - p);
  return dot(q, q);
}

namespace {

// Eigen-decomposition of the symmetric 3x3 matrix `a` by cyclic Jacobi rotations (Golub and Van Loan 8.5): the
// eigenvalues on the returned diagonal, the eigenvectors the columns of `v`. Converges quadratically; the loop ends
// when a sweep leaves every off-diagonal entry zero or negligible against the diagonal.
void jacobiEigen(double a[3][3], double v[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v[i][j] = i == j;
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = std::fabs(a[0][1]) + std::fabs(a[0][2]) + std::fabs(a[1][2]);
    const double diag = std::fabs(a[0][0]) + std::fabs(a[1][1]) + std::fabs(a[2][2]);
    if (off == 0 || off < 1e-18 * diag) return;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // a <- a J (columns p, q)
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq, a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // a <- J^T a (rows p, q)
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk, a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq, v[k][q] = s * vkp + c * vkq;
        }
      }
  }
}

double robustLength(double a, double b, double c = 0) {
  const double m = std::max({std::fabs(a), std::fabs(b), std::fabs(c)});
  if (m == 0) return 0;
  a /= m, b /= m, c /= m;
  return m * std::sqrt(a * a + b * b + c * c);
}

// Eberly's bisection for the root of sum_i (r_i z_i / (s + r_i))^2 = 1 (r_last = 1), in the shifted unknown
// t = s + 1: the last term is then z_last / t, which stays accurate when the point lies near the shortest axis's
// plane (t tiny), where s + 1 would cancel. Runs until the midpoint equals an end: the root to the last bit.
template <int N>
double bisectShiftedRoot(const double (&r)[N], const double (&z)[N], double g) {
  double n[N], q[N];  // numerators r_i z_i and shifts r_i - 1 (0 for the last axis)
  for (int i = 0; i < N; ++i) n[i] = r[i] * z[i], q[i] = r[i] - 1;
  q[N - 1] = 0;
  double t0 = z[N - 1];
  double t1 = g < 0 ? 1 : (N == 2 ? robustLength(n[0], n[1]) : robustLength(n[0], n[1], n[N - 1]));
  double t = t0;
  for (int it = 0; it < 2200; ++it) {
    t = 0.5 * (t0 + t1);
    if (t == t0 || t == t1) break;
    double f = -1;
    for (int i = 0; i < N; ++i) {
      const double ratio = n[i] / (t + q[i]);
      f += ratio * ratio;
    }
    if (f > 0)
      t0 = t;
    else if (f < 0)
      t1 = t;
    else
      break;
  }
  return t;
}

// Closest point on the ellipse of semi-axes e0 >= e1 > 0 to (y0, y1), both >= 0 (Eberly 2013, section 2.9).
std::array<double, 2> closestOnEllipse(double e0, double e1, double y0, double y1) {
  if (y1 > 0) {
    if (y0 > 0) {
      const double z0 = y0 / e0, z1 = y1 / e1, g = z0 * z0 + z1 * z1 - 1;
      if (g == 0) return {y0, y1};
      const double r0 = (e0 / e1) * (e0 / e1);
      const double t = bisectShiftedRoot<2>({r0, 1}, {z0, z1}, g);
      return {r0 * y0 / (t + (r0 - 1)), y1 / t};
    }
    return {0, e1};
  }
  const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
  if (numer0 < denom0) {
    const double xde0 = numer0 / denom0;
    return {e0 * xde0, e1 * std::sqrt(std::max(0.0, 1 - xde0 * xde0))};
  }
  return {e0, 0};
}

// Closest point on the ellipsoid of semi-axes e0 >= e1 >= e2 > 0 to y, all y_i >= 0 (Eberly 2013, section 3.9).
std::array<double, 3> closestOnEllipsoid(const double e[3], const double y[3]) {
  if (y[2] > 0) {
    if (y[1] > 0) {
      if (y[0] > 0) {
        const double z0 = y[0] / e[0], z1 = y[1] / e[1], z2 = y[2] / e[2];
        const double g = z0 * z0 + z1 * z1 + z2 * z2 - 1;
        if (g == 0) return {y[0], y[1], y[2]};
        const double r0 = (e[0] / e[2]) * (e[0] / e[2]), r1 = (e[1] / e[2]) * (e[1] / e[2]);
        const double t = bisectShiftedRoot<3>({r0, r1, 1}, {z0, z1, z2}, g);
        return {r0 * y[0] / (t + (r0 - 1)), r1 * y[1] / (t + (r1 - 1)), y[2] / t};
      }
      const auto x = closestOnEllipse(e[1], e[2], y[1], y[2]);
      return {0, x[0], x[1]};
    }
    if (y[0] > 0) {
      const auto x = closestOnEllipse(e[0], e[2], y[0], y[2]);
      return {x[0], 0, x[1]};
    }
    return {0, 0, e[2]};
  }
  const double denom0 = e[0] * e[0] - e[2] * e[2], denom1 = e[1] * e[1] - e[2] * e[2];
  const double numer0 = e[0] * y[0], numer1 = e[1] * y[1];
  if (numer0 < denom0 && numer1 < denom1) {
    const double xde0 = numer0 / denom0, xde1 = numer1 / denom1;
    const double discr = 1 - xde0 * xde0 - xde1 * xde1;
    if (discr > 0) return {e[0] * xde0, e[1] * xde1, e[2] * std::sqrt(discr)};
  }
  const auto x = closestOnEllipse(e[0], e[1], y[0], y[1]);
  return {x[0], x[1], 0};
}

}  // namespace

std::array<Vec3, 3> symmetricEigenvectors(const std::array<std::array<double, 3>, 3>& m) {
  double a[3][3], v[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = m[i][j];
  jacobiEigen(a, v);
  return {Vec3{v[0][0], v[1][0], v[2][0]}, Vec3{v[0][1], v[1][1], v[2][1]}, Vec3{v[0][2], v[1][2], v[2][2]}};
}

EllipsoidShape ellipsoidShape(const Sphere& sphere) {
  EllipsoidShape shape;
  if (!sphere.isEllipsoid()) {
    shape.center = sphere.center;
    shape.semi = {sphere.radius, sphere.radius, sphere.radius};
    return shape;
  }
  shape.center = transformPoint(sphere.transform, sphere.center);
  double lt[3][3], v[3][3];  // L L^T, L the transform's linear part
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      lt[i][j] = 0;
      for (int k = 0; k < 3; ++k) lt[i][j] += sphere.transform.m[i][k] * sphere.transform.m[j][k];
    }
  jacobiEigen(lt, v);
  int order[3] = {0, 1, 2};  // descending eigenvalues: Eberly's e0 >= e1 >= e2
  std::sort(order, order + 3, [&](int p, int q) { return lt[p][p] > lt[q][q]; });
  for (int i = 0; i < 3; ++i) {
    const int c = order[i];
    if (!(lt[c][c] > 0)) fail<InputError>("ellipsoid with a singular transform");
    shape.axes[i] = {v[0][c], v[1][c], v[2][c]};
    shape.semi.at(i) = sphere.radius * std::sqrt(lt[c][c]);
  }
  shape.isSphere = shape.semi.x == shape.semi.z;
  return shape;
}

Vec3 closestPointOnEllipsoid(const EllipsoidShape& shape, const Vec3& p) {
  const Vec3 d = p - shape.center;
  if (shape.isSphere) {
    const double len = length(d);
    // The centre is equidistant from the whole sphere; any surface point is nearest.
    return len > 0 ? shape.center + d * (shape.semi.x / len) : shape.center + Vec3{shape.semi.x, 0, 0};
  }
  const double e[3] = {shape.semi.x, shape.semi.y, shape.semi.z};
  double y[3];
  for (int i = 0; i < 3; ++i) y[i] = std::fabs(dot(d, shape.axes[i]));
  const std::array<double, 3> x = closestOnEllipsoid(e, y);
  Vec3 out = shape.center;
  for (int i = 0; i < 3; ++i) out = out + shape.axes[i] * std::copysign(x[i], dot(d, shape.axes[i]));
  return out;
}

bool insideEllipsoid(const EllipsoidShape& shape, const Vec3& p) {
  const Vec3 d = p - shape.center;
  double sum = 0;
  for (int i = 0; i < 3; ++i) {
    const double u = dot(d, shape.axes[i]) / shape.semi[i];
    sum += u * u;
  }
  return sum < 1;
}

TriangleLowerBound triangleLowerBound(const Triangle& t) {
  TriangleLowerBound b;
  const Vec3 ab = t.v[1] - t.v[0], ac = t.v[2] - t.v[0], bc = t.v[2] - t.v[1];
  const Vec3 n = cross(ab, ac);
  const double area2 = length(n), product = length(ab) * length(ac);
  // The normal's direction errs by a few ulps times this conditioning (the cross product of two near-parallel
  // edges cancels); every later rounding is a few ulps of |p - corner|. 1e-13 per unit covers both with a wide
  // margin, and a conditioning past 1e6 (a needle) is not used at all.
  const double conditioning = product / area2;
  if (!(area2 > 0) || !(conditioning < 1e6)) return b;
  b.normal = n / area2;
  const Vec3 edges[3] = {ab, bc, t.v[0] - t.v[2]};
  for (int e = 0; e < 3; ++e) b.edgeNormals[e] = normalize(cross(edges[e], b.normal));
  const auto l1 = [](const Vec3& v) { return std::fabs(v.x) + std::fabs(v.y) + std::fabs(v.z); };
  b.slack = 1e-13 * conditioning;
  b.slackAt0 = b.slack * std::max({l1(ab), l1(ac), l1(bc)});
  b.usable = true;
  return b;
}

double squaredDistanceToTriangleWithin(const Triangle& t, const TriangleLowerBound& bound, const Vec3& p,
                                       double bound2) {
  if (bound.usable) {
    const Vec3 pa = p - t.v[0];
    const double err = bound.slack * (std::fabs(pa.x) + std::fabs(pa.y) + std::fabs(pa.z)) + bound.slackAt0;
    const double h = std::max(0.0, std::fabs(dot(bound.normal, pa)) - err);
    const double outside = std::max(
        {dot(bound.edgeNormals[0], pa), dot(bound.edgeNormals[1], p - t.v[1]), dot(bound.edgeNormals[2], p - t.v[2])});
    const double s = std::max(0.0, outside - err);
    if (h * h + s * s > bound2) return INFINITY;
  }
  return squaredDistanceToTriangle(t.v[0], t.v[1], t.v[2], p);
}

Box ellipsoidBounds(const EllipsoidShape& shape) {
  const double big = shape.semi.x;
  return {shape.center - Vec3{big, big, big}, shape.center + Vec3{big, big, big}};
}

}  // namespace vox
