// Generalized winding number: 1 inside and 0 outside a closed outward surface, -1 inside it inverted; the tree of
// Barill et al. against the exact sum on a real mesh.
#include <gtest/gtest.h>

#include <random>

#include "vox/import/import.h"
#include "vox/voxelize/winding_number.h"

namespace vox {
namespace {

std::vector<Triangle> boxTriangles(double a, double b, bool inward) {
  Vec3 p[8];
  for (int c = 0; c < 8; ++c) p[c] = {(c & 1) ? b : a, (c & 2) ? b : a, (c & 4) ? b : a};
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Triangle> t;
  for (const auto& q : quads) {
    t.push_back({{p[q[0]], p[q[1]], p[q[2]]}});
    t.push_back({{p[q[0]], p[q[2]], p[q[3]]}});
  }
  if (inward)
    for (Triangle& tri : t) std::swap(tri.v[1], tri.v[2]);
  return t;
}

TEST(WindingNumber, ClosedCubeInsideOutsideAndOrientation) {
  const auto out = boxTriangles(0, 1, false), in = boxTriangles(0, 1, true);
  EXPECT_NEAR(windingNumberExact(out, {0.5, 0.5, 0.5}), 1, 1e-12);
  EXPECT_NEAR(windingNumberExact(out, {0.01, 0.99, 0.3}), 1, 1e-9);
  EXPECT_NEAR(windingNumberExact(out, {1.5, 0.5, 0.5}), 0, 1e-12);
  EXPECT_NEAR(windingNumberExact(out, {-3, 7, 2}), 0, 1e-12);
  EXPECT_NEAR(windingNumberExact(in, {0.5, 0.5, 0.5}), -1, 1e-12);
  // One face removed: at the centre the five faces subtend 5/6 of the sphere; at the hole's centre exactly half.
  const std::vector<Triangle> open(out.begin(), out.end() - 2);
  EXPECT_NEAR(windingNumberExact(open, {0.5, 0.5, 0.5}), 5.0 / 6, 1e-12);
  EXPECT_NEAR(windingNumberExact(open, {1, 0.5, 0.5}), 0.5, 1e-12);
  // The sign convention of triangleWindingNumber: seen from the side opposite to its normal it is positive.
  EXPECT_GT(triangleWindingNumber({0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {0, 0, 0}), 0);
  EXPECT_EQ(triangleWindingNumber({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}), 0);  // degenerate
  const WindingTree tree = buildWindingTree(out);
  EXPECT_NEAR(windingNumber(tree, {0.5, 0.5, 0.5}), 1, 1e-12);
  EXPECT_NEAR(windingNumber(buildWindingTree({}), {0, 0, 0}), 0, 0);
}

TEST(WindingNumber, TreeMatchesExactSumOnTheCourseBunny) {
  const Scene bunny = loadScene(std::string(VOX_SEED_DIR) + "/6837/scenes/bunny_1k.obj");
  const WindingTree tree = buildWindingTree(bunny.triangles);
  const Box b = *sceneBounds(bunny);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  double worst2 = 0, worst8 = 0;
  int inside = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 q{b.lo.x + u(rng) * (b.hi.x - b.lo.x), b.lo.y + u(rng) * (b.hi.y - b.lo.y),
                 b.lo.z + u(rng) * (b.hi.z - b.lo.z)};
    const double exact = windingNumberExact(bunny.triangles, q);
    inside += exact > 0.5;
    worst2 = std::max(worst2, std::abs(windingNumber(tree, q) - exact));
    worst8 = std::max(worst8, std::abs(windingNumber(tree, q, 8) - exact));
  }
  EXPECT_GT(inside, 20);  // the points probe the inside too
  EXPECT_LT(worst2, 0.02) << worst2;
  EXPECT_LT(worst8, 2e-3) << worst8;
}

}  // namespace
}  // namespace vox
