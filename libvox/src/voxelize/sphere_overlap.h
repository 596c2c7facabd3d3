// Does the surface of a sphere or ellipsoid meet a closed box? Written once, generic in the number type, so that
// the same algorithm runs in double (the `sat` method), in CGAL's interval arithmetic (the filter of `exact`) and in
// CGAL's exact rationals (its fallback).
//
// The ellipsoid is {M p : |p - c| <= r} with M = [L t]. With B = adj(L) (so L^-1 = B / det L), a world point x is
// inside iff f(x) = |B (x - t) - det(L) c|^2 <= (det(L) r)^2: polynomial in the inputs, no division, no root.
// The surface meets the box iff min over the box of f <= R^2 <= max over the box of f. f is convex, so its
// maximum is at a corner, and its minimum lies in the relative interior of exactly one of the box's 27 faces
// (interior, 6 sides, 12 edges, 8 corners), where it is the unconstrained minimiser of f restricted to that
// face's affine hull: enumerating the faces and keeping feasible minimisers finds it exactly.
#pragma once

#include <algorithm>
#include <array>

#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

template <typename NT>
using Vec3T = std::array<NT, 3>;

namespace sphere_overlap {

// A plain sphere: the closed-form nearest and farthest points of the box.
template <typename NT>
bool sphereMeetsBox(const Sphere& s, const double lo[3], const double hi[3]) {
  const double c[3] = {s.center.x, s.center.y, s.center.z};
  NT minD(0);
  for (int a = 0; a < 3; ++a) {
    if (c[a] < lo[a]) {
      const NT d = NT(lo[a]) - NT(c[a]);
      minD += d * d;
    } else if (c[a] > hi[a]) {
      const NT d = NT(hi[a]) - NT(c[a]);
      minD += d * d;
    }
  }
  const NT r2 = NT(s.radius) * NT(s.radius);
  if (!(minD <= r2)) return false;
  for (int corner = 0; corner < 8; ++corner) {
    NT d2(0);
    for (int a = 0; a < 3; ++a) {
      const NT d = NT(((corner >> a) & 1) ? hi[a] : lo[a]) - NT(c[a]);
      d2 += d * d;
    }
    if (d2 >= r2) return true;
  }
  return false;
}

// The ellipsoid as f(x) = |B x - e|^2 <= R2 (see the top of the file): B = adj(L), e = B t + det(L) c,
// R2 = (det(L) r)^2.
template <typename NT>
struct Quadric {
  NT B[3][3], e[3], R2;

  explicit Quadric(const Sphere& s) {
    const auto& m = s.transform.m;
    NT L[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) L[r][c] = NT(m[r][c]);
    B[0][0] = L[1][1] * L[2][2] - L[1][2] * L[2][1];
    B[0][1] = L[0][2] * L[2][1] - L[0][1] * L[2][2];
    B[0][2] = L[0][1] * L[1][2] - L[0][2] * L[1][1];
    B[1][0] = L[1][2] * L[2][0] - L[1][0] * L[2][2];
    B[1][1] = L[0][0] * L[2][2] - L[0][2] * L[2][0];
    B[1][2] = L[0][2] * L[1][0] - L[0][0] * L[1][2];
    B[2][0] = L[1][0] * L[2][1] - L[1][1] * L[2][0];
    B[2][1] = L[0][1] * L[2][0] - L[0][0] * L[2][1];
    B[2][2] = L[0][0] * L[1][1] - L[0][1] * L[1][0];
    const NT det = L[0][0] * B[0][0] + L[0][1] * B[1][0] + L[0][2] * B[2][0];
    const NT t[3] = {NT(m[0][3]), NT(m[1][3]), NT(m[2][3])};
    const NT c[3] = {NT(s.center.x), NT(s.center.y), NT(s.center.z)};
    for (int r = 0; r < 3; ++r) e[r] = B[r][0] * t[0] + B[r][1] * t[1] + B[r][2] * t[2] + det * c[r];
    const NT R = det * NT(s.radius);
    R2 = R * R;
  }
  NT f(const NT x[3]) const {
    NT sum(0);
    for (int r = 0; r < 3; ++r) {
      const NT d = B[r][0] * x[0] + B[r][1] * x[1] + B[r][2] * x[2] - e[r];
      sum += d * d;
    }
    return sum;
  }
};

// Solves the n x n system A y = b (n = 1, 2, 3) by Cramer's rule.
template <typename NT>
void solveCramer(const NT A[3][3], const NT b[3], int n, NT y[3]) {
  if (n == 1) {
    y[0] = b[0] / A[0][0];
  } else if (n == 2) {
    const NT d = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    y[0] = (b[0] * A[1][1] - A[0][1] * b[1]) / d;
    y[1] = (A[0][0] * b[1] - b[0] * A[1][0]) / d;
  } else {
    auto det3 = [](const NT M[3][3]) {
      return M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
             M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
    };
    const NT d = det3(A);
    for (int k = 0; k < 3; ++k) {
      NT Ak[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Ak[i][j] = (j == k) ? b[i] : A[i][j];
      y[k] = det3(Ak) / d;
    }
  }
}

// The minimiser x of f over the affine hull of one of the box's 27 faces (state per axis: 0 = lo, 1 = hi,
// 2 = free); false when it lies outside the face.
template <typename NT>
bool faceMinimizer(const Quadric<NT>& q, int face, const double lo[3], const double hi[3], NT x[3]) {
  const int state[3] = {face % 3, (face / 3) % 3, face / 9};
  int freeAxes[3], nFree = 0;
  for (int a = 0; a < 3; ++a) {
    if (state[a] == 2) {
      freeAxes[nFree++] = a;
      x[a] = NT(0);
    } else {
      x[a] = NT(state[a] ? hi[a] : lo[a]);
    }
  }
  if (nFree == 0) return true;
  // Least squares for the free coordinates: (Bf^T Bf) y = Bf^T (e - B x_fixed).
  NT rhs0[3];
  for (int r = 0; r < 3; ++r) rhs0[r] = q.e[r] - (q.B[r][0] * x[0] + q.B[r][1] * x[1] + q.B[r][2] * x[2]);
  NT A[3][3], b[3];
  for (int i = 0; i < nFree; ++i) {
    b[i] = NT(0);
    for (int r = 0; r < 3; ++r) b[i] += q.B[r][freeAxes[i]] * rhs0[r];
    for (int j = 0; j < nFree; ++j) {
      A[i][j] = NT(0);
      for (int r = 0; r < 3; ++r) A[i][j] += q.B[r][freeAxes[i]] * q.B[r][freeAxes[j]];
    }
  }
  NT y[3];
  solveCramer(A, b, nFree, y);
  for (int i = 0; i < nFree; ++i) {
    const int a = freeAxes[i];
    if (y[i] < NT(lo[a]) || y[i] > NT(hi[a])) return false;
    x[a] = y[i];
  }
  return true;
}

}  // namespace sphere_overlap

template <typename NT>
bool sphereSurfaceMeetsBox(const Sphere& s, const Box& box) {
  const double lo[3] = {box.lo.x, box.lo.y, box.lo.z};
  const double hi[3] = {box.hi.x, box.hi.y, box.hi.z};
  if (!s.isEllipsoid()) return sphere_overlap::sphereMeetsBox<NT>(s, lo, hi);
  const sphere_overlap::Quadric<NT> q(s);
  // Maximum at a corner.
  bool someCornerOutside = false;
  for (int corner = 0; corner < 8 && !someCornerOutside; ++corner) {
    const NT x[3] = {NT((corner & 1) ? hi[0] : lo[0]), NT((corner & 2) ? hi[1] : lo[1]),
                     NT((corner & 4) ? hi[2] : lo[2])};
    if (q.f(x) >= q.R2) someCornerOutside = true;
  }
  if (!someCornerOutside) return false;  // box strictly inside the ellipsoid
  // Minimum: in the relative interior of one face, where it is that face's unconstrained minimiser.
  for (int face = 0; face < 27; ++face) {
    NT x[3];
    if (!sphere_overlap::faceMinimizer(q, face, lo, hi, x)) continue;
    if (q.f(x) <= q.R2) return true;  // some point of the box is inside or on, and some corner is on or outside
  }
  return false;
}

}  // namespace vox
