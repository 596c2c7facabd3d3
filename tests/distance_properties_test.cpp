// Invariants of the distance and volume stages, held by property-based tests (RapidCheck; issue 45), over random
// closed, inside-out, open and self-intersecting meshes, random bounds (the scene's, around, inside, cutting and
// outside it), every overlap method and small grids:
//  - the --sdf band equals the dense field at its cells and holds exactly the cells the field puts within HALF
//    smallest cell edges; the dense field equals pointDistances at every cell centre, bit for bit, sign included;
//  - fractions lie in [0, 1] and, with the fill's solid cells, sum to the exact volume of a box inside the bounds;
//  - a scene scaled by 2^k has its band scaled by 2^k, bit for bit, and the same fractions.
// ctest runs a fixed seed and a bounded count (RC_PARAMS in CMakeLists.txt); a longer run by hand:
// RC_PARAMS="max_success=2000" build/vox_tests --gtest_filter='DistanceProperties.*'.
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <ostream>
#include <vector>

#include "vox/core/error.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

constexpr int kBoxFaces[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                  {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};

void addBox(Scene& s, const Vec3& lo, const Vec3& hi, bool insideOut = false) {
  const Vec3 v[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                     {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  for (const auto& f : kBoxFaces) {
    Triangle t;
    t.v = {v[f[0]], v[insideOut ? f[2] : f[1]], v[insideOut ? f[1] : f[2]]};
    s.triangles.push_back(t);
  }
}

// Coordinates in eighths: faces on cell boundaries and cell-centre planes, the adversarial cases.
rc::Gen<double> eighths(int lo, int hi) {
  return rc::gen::map(rc::gen::inRange(lo, hi + 1), [](int n) { return n / 8.0; });
}

rc::Gen<Vec3> points(int lo, int hi) {
  return rc::gen::apply(
      [](double x, double y, double z) {
        return Vec3{x, y, z};
      },
      eighths(lo, hi), eighths(lo, hi), eighths(lo, hi));
}

struct BoxSpec {
  Vec3 lo, hi;
};

void showValue(const BoxSpec& b, std::ostream& os) {
  os << "box (" << b.lo.x << ", " << b.lo.y << ", " << b.lo.z << ") - (" << b.hi.x << ", " << b.hi.y << ", " << b.hi.z
     << ")";
}

rc::Gen<BoxSpec> boxes() {
  return rc::gen::apply([](Vec3 lo, Vec3 size) { return BoxSpec{lo, lo + size}; }, points(-16, 24), points(1, 16));
}

// A closed box, an inside-out box, two overlapping boxes, a box with faces missing, or a triangle soup.
Scene drawScene() {
  Scene s;
  const int kind = *rc::gen::inRange(0, 5);
  if (kind <= 2) {
    const BoxSpec b = *boxes();
    addBox(s, b.lo, b.hi, kind == 1);
    if (kind == 2) {
      const BoxSpec c = *boxes();
      addBox(s, c.lo, c.hi);
    }
  } else if (kind == 3) {
    const BoxSpec b = *boxes();
    addBox(s, b.lo, b.hi);
    const auto keep = *rc::gen::container<std::vector<bool>>(6, rc::gen::arbitrary<bool>());
    decltype(s.triangles) kept;
    for (size_t t = 0; t < 12; ++t)
      if (keep[t / 2]) kept.push_back(s.triangles[t]);
    RC_PRE(!kept.empty() && kept.size() < 12);
    s.triangles = kept;
  } else {
    const int n = *rc::gen::inRange(1, 6);
    for (int t = 0; t < n; ++t) {
      Triangle tri;
      tri.v = {*points(-16, 24), *points(-16, 24), *points(-16, 24)};
      s.triangles.push_back(tri);
    }
  }
  return s;
}

// The scene's bounds, or bounds around, inside, cutting or outside its box.
std::optional<Box> drawBounds(const Scene& s) {
  const Box b = *sceneBounds(s);
  const int how = *rc::gen::inRange(0, 5);
  const Vec3 span{std::max(b.hi.x - b.lo.x, 0.25), std::max(b.hi.y - b.lo.y, 0.25), std::max(b.hi.z - b.lo.z, 0.25)};
  switch (how) {
    case 0:
      return std::nullopt;
    case 1:
      return Box{b.lo - span * 0.25 - *points(0, 4), b.hi + span * 0.25 + *points(0, 4)};
    case 2:
      return Box{b.lo + span * 0.25, b.lo + span * 0.25 + span * 0.5};
    case 3: {
      const Vec3 a = b.lo + span * 0.5 - *points(0, 8);
      return Box{a, a + span + *points(1, 8)};
    }
    default: {
      const Vec3 a = b.hi + *points(1, 8);
      return Box{a, a + *points(1, 8)};
    }
  }
}

VoxelizeOptions drawOptions(const Scene& s) {
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{uint32_t(*rc::gen::inRange(1, 9)), uint32_t(*rc::gen::inRange(1, 9)),
                                   uint32_t(*rc::gen::inRange(1, 9))};
  o.bounds = drawBounds(s);
  return o;
}

// The dense field as libvox.sdf makes it: an exact grid of the same cells, filled.
std::vector<double> denseField(const Scene& s, VoxelizeOptions o) {
  o.method = OverlapMethod::Exact;
  Grid g = voxelizeScene(s, o);
  fillSolid(g, s);
  std::vector<double> field(g.cellCount());
  denseSignedDistances(g, s, field, {1, g.dims[0], uint64_t(g.dims[0]) * g.dims[1]});
  return field;
}

double smallestEdge(const Grid& g) {
  double e = INFINITY;
  for (int a = 0; a < 3; ++a) e = std::min(e, (g.bounds.hi[a] - g.bounds.lo[a]) / g.dims[a]);
  return e;
}

RC_GTEST_PROP(DistanceProperties, BandEqualsDenseFieldEqualsPointQueries, ()) {
  const Scene s = drawScene();
  VoxelizeOptions o = drawOptions(s);
  o.method = *rc::gen::element(OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox, OverlapMethod::Center);
  const double half = *rc::gen::element(1.0, 2.5, 3.0);
  Grid g;
  try {
    g = voxelizeScene(s, o);
  } catch (const Error&) {
    RC_DISCARD("refused");
  }
  SdfOptions so;
  so.halfWidth = half;
  storeSignedDistances(g, s, so, false);
  const std::vector<double> field = denseField(s, o);
  RC_ASSERT(field.size() == g.cellCount());
  std::vector<uint64_t> within;
  for (uint64_t key = 0; key < field.size(); ++key) {
    RC_ASSERT(!std::isnan(field[key]));
    if (std::fabs(field[key]) <= half * smallestEdge(g)) within.push_back(key);
  }
  RC_ASSERT(g.sdfKeys == within);
  for (size_t b = 0; b < g.sdfKeys.size(); ++b) RC_ASSERT(g.sdfValues[b] == field[g.sdfKeys[b]]);
  std::vector<double> centres;
  for (uint64_t key = 0; key < field.size(); ++key) {
    const Vec3 c = cellCentre(g, key);
    centres.insert(centres.end(), {c.x, c.y, c.z});
  }
  std::vector<double> d(field.size()), closest(3 * field.size());
  std::vector<int64_t> prim(field.size());
  pointDistances(s, centres, true, {d, prim, closest});
  for (uint64_t key = 0; key < field.size(); ++key) RC_ASSERT(d[key] == field[key]);
}

RC_GTEST_PROP(DistanceProperties, FractionsSumToTheVolumeInsideTheBounds, ()) {
  const BoxSpec box = *boxes();
  Scene s;
  addBox(s, box.lo, box.hi);
  VoxelizeOptions o = drawOptions(s);
  Grid g;
  try {
    g = voxelizeScene(s, o);
  } catch (const Error&) {
    RC_DISCARD("refused");
  }
  fillSolid(g, s, fillForFractions({}));
  const std::vector<double> fractions = volumeFractions(g, s);
  RC_ASSERT(fractions.size() == g.cellKeys.size());
  double sum = double(g.solidCount());
  for (double f : fractions) {
    RC_ASSERT(f >= 0.0);
    RC_ASSERT(f <= 1.0);
    sum += f;
  }
  double cell = 1, exact = 1;
  for (int a = 0; a < 3; ++a) {
    cell *= (g.bounds.hi[a] - g.bounds.lo[a]) / g.dims[a];
    exact *= std::max(0.0, std::min(box.hi[a], g.bounds.hi[a]) - std::max(box.lo[a], g.bounds.lo[a]));
  }
  RC_ASSERT(std::fabs(sum * cell - exact) <= 1e-12 * std::max(exact, cell));
}

RC_GTEST_PROP(DistanceProperties, ScaledScenesGiveScaledAnswers, ()) {
  const Scene s = drawScene();
  const int k = *rc::gen::inRange(-1000, 1001);
  const double scale = std::ldexp(1.0, k);
  Scene scaled = s;
  for (Triangle& t : scaled.triangles)
    for (Vec3& v : t.v) v = v * scale;
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{uint32_t(*rc::gen::inRange(1, 9)), uint32_t(*rc::gen::inRange(1, 9)),
                                   uint32_t(*rc::gen::inRange(1, 9))};
  Grid g1, gk;
  try {
    g1 = voxelizeScene(s, o);
  } catch (const Error&) {
    RC_DISCARD("refused");
  }
  gk = voxelizeScene(scaled, o);
  SdfOptions so;
  so.halfWidth = 2;
  storeSignedDistances(g1, s, so, false);
  storeSignedDistances(gk, scaled, so, false);
  RC_ASSERT(gk.cellKeys == g1.cellKeys);
  RC_ASSERT(gk.sdfKeys == g1.sdfKeys);
  for (size_t b = 0; b < g1.sdfValues.size(); ++b) RC_ASSERT(gk.sdfValues[b] == g1.sdfValues[b] * scale);
}

}  // namespace
}  // namespace vox
