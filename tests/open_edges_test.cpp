// Open edges: counted after welding equal positions, grouped into boundaries with the area of their cap.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "vox/voxelize/open_edges.h"
#include "vox/voxelize/winding_number.h"

namespace vox {
namespace {

std::vector<Triangle> cube() {
  Vec3 p[8];
  for (int c = 0; c < 8; ++c) p[c] = {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)};
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Triangle> t;
  for (const auto& q : quads) {
    t.push_back({{p[q[0]], p[q[1]], p[q[2]]}});
    t.push_back({{p[q[0]], p[q[2]], p[q[3]]}});
  }
  return t;
}

TEST(OpenEdges, ClosedOpenAndNonManifold) {
  auto t = cube();
  EXPECT_EQ(countOpenEdges(t), 0u);
  EXPECT_TRUE(openBoundaries(t).empty());
  // A second closed cube sharing nothing, and a degenerate triangle with welded ends: still closed.
  t.push_back({{Vec3{0, 0, 0}, Vec3{0, 0, 0}, Vec3{0, 0, 0}}});
  EXPECT_EQ(countOpenEdges(t), 0u);
  t.pop_back();
  // Top face (z = 1) removed: its square rim, one boundary of length 4 capped by the unit square.
  auto open = t;
  open.erase(open.begin() + 2, open.begin() + 4);
  EXPECT_EQ(countOpenEdges(open), 4u);
  const auto b = openBoundaries(open);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].edges, 4u);
  EXPECT_DOUBLE_EQ(b[0].length, 4);
  EXPECT_DOUBLE_EQ(b[0].capArea, 1);
  EXPECT_DOUBLE_EQ(b[0].bounds.lo.z, 1);
  // A third triangle on an edge of the closed cube: three uses, odd, so that edge and the fin's two are open.
  t.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0.5, -1, 0.5}}});
  EXPECT_EQ(countOpenEdges(t), 3u);
  // A whole cube flipped inside out is closed too; one flipped face is closed but an oriented seam.
  auto flipped = cube();
  std::swap(flipped[0].v[1], flipped[0].v[2]);
  std::swap(flipped[1].v[1], flipped[1].v[2]);
  EXPECT_EQ(countOpenEdges(flipped), 0u);
  EXPECT_EQ(openBoundaries(flipped).size(), 1u);
}

// The caps close the mesh: with them every edge is balanced, and the winding number is an integer off the surface
// (1 inside the capped box, 0 outside), whatever the holes, their orientation seams and repeated edges.
void expectCapsClose(const std::vector<Triangle>& mesh, uint32_t seed) {
  std::vector<Triangle> closed = mesh;
  for (const OpenBoundary& b : openBoundaries(mesh)) closed.insert(closed.end(), b.cap.begin(), b.cap.end());
  EXPECT_TRUE(openBoundaries(closed).empty());
  EXPECT_EQ(countOpenEdges(closed), 0u);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  for (int i = 0; i < 200; ++i) {
    const Vec3 q{u(rng), u(rng), u(rng)};
    const double w = windingNumberExact(closed, q);
    EXPECT_NEAR(w, std::round(w), 1e-9) << q.x << " " << q.y << " " << q.z;
  }
}

TEST(OpenEdges, CapsCloseTheMesh) {
  auto open = cube();
  open.erase(open.begin() + 2, open.begin() + 4);  // one hole
  expectCapsClose(open, 1);
  open.erase(open.begin() + 4, open.begin() + 6);  // two faces gone: one larger hole, not planar
  expectCapsClose(open, 2);
  auto flipped = cube();  // an orientation seam, and a face used twice
  std::swap(flipped[0].v[1], flipped[0].v[2]);
  std::swap(flipped[1].v[1], flipped[1].v[2]);
  flipped.push_back(flipped[5]);
  expectCapsClose(flipped, 3);
  auto lone = cube();                          // two disjoint holes on opposite faces
  lone.erase(lone.begin(), lone.begin() + 4);  // z = 0 and z = 1
  const auto b = openBoundaries(lone);
  EXPECT_EQ(b.size(), 2u);
  expectCapsClose(lone, 4);
}

}  // namespace
}  // namespace vox
