// The volume of a ball and an axis-aligned box (volume fractions of spheres).
#pragma once

#include "vox/core/math.h"

namespace vox::volume {

// Volume of {p : |p - center| <= radius} and the closed box `box`, world units cubed. The cross-section at height z
// (a disk and a rectangle) has a closed form without cancellation (trapezoids under chords plus circular segments);
// its integral over z is split where the section changes form (the disk's circle passing a rectangle corner or
// side line), each piece mapped by z = a + (b - a)(1 - cos t)/2 so that the square-root ends become smooth, and
// integrated by Gauss-Legendre of 20 and 40 points, halving a piece while the two differ by more than 1e-15 of the
// box's volume. Error: below 1e-13 of the box volume for radius up to 1000 box edges (tested against 4/3 pi r^3
// and against an independent quadrature).
double ballBoxVolume(const Vec3& center, double radius, const Box& box);

// Area of the disk of radius rho about the origin and the rectangle [u0, u1] x [v0, v1]; exposed for tests.
double diskRectArea(double rho, double u0, double u1, double v0, double v1);

}  // namespace vox::volume
