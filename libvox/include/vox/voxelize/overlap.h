// Primitive-cell overlap tests, one per method (DESIGN.md "Overlap methods"). Boxes are closed.
// Triangles and spheres are surfaces: a sphere meets a box when the box is neither entirely outside the ball
// nor strictly inside it.
#pragma once

#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

// exact: CGAL exact predicates; no epsilon; correct for any finite double input, degenerate triangles included.
bool triangleBoxExact(const Triangle& t, const Box& box);
bool sphereBoxExact(const Sphere& s, const Box& box);

// sat: the separating-axis test of Akenine-Moller 2001 in double precision (13 axes, relative to the first vertex)
// and the sphere test in interval arithmetic, with no exact fallback: where rounding cannot decide a contact, the
// cell is taken. So sat never misses a cell the exact test takes; it may add a few at exact contacts.
bool triangleBoxSat(const Triangle& t, const Box& box);
bool sphereBoxSat(const Sphere& s, const Box& box);

// Filtered exact triangle test: a double-precision separating-axis test with a conservative error bound decides
// almost every case; it calls triangleBoxExact only when the bound cannot. `usedFallback` reports which.
bool triangleBoxFiltered(const Triangle& t, const Box& box, bool* usedFallback = nullptr);
bool sphereBoxFiltered(const Sphere& s, const Box& box, bool* usedFallback = nullptr);

}  // namespace vox
