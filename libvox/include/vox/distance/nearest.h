// The bounded primitive nearest to any point (DESIGN.md "Distance and volume": Grid.distance, libvox.sdf): a
// bounding volume hierarchy over the scene's triangles, spheres and ellipsoids (planes are left out), four children
// per node, queried depth first, nearer child first, pruned by proven lower bounds tested four at a time in float
// (SSE2): each child's axis-aligned box and each leaf triangle's plane and edges (triangleLowerBound), lowered by a
// rounding allowance that keeps them below the double bounds they stand for (nearest.cpp). Only survivors get the
// exact double distance the --sdf band uses (squaredDistanceToTriangleWithin, closestPointOnEllipsoid), so a dense
// field equals the band bit for bit and the answer is the one a double search or brute force gives.
#pragma once

#include <cstdint>
#include <vector>

#include "vox/core/math.h"
#include "vox/core/power_of_two_frame.h"
#include "vox/core/scene.h"
#include "vox/distance/closest_point.h"

namespace vox {

struct NearestHit {
  double squaredDistance = INFINITY;
  int64_t primitive = -1;  // the grid's ids: triangles, then spheres; -1 when nothing is within the bound
};

class NearestPrimitive {
 public:
  // Copies what it needs from `scene` (about 350 bytes per primitive, with the nodes). Throws InputError for a singular
  // sphere transform (ellipsoidShape).
  explicit NearestPrimitive(const Scene& scene);
  // The same over the scene scaled into `frame` (vox/core/power_of_two_frame.h): points given to the queries below
  // and the distances and points they return are then in that frame.
  NearestPrimitive(const Scene& scene, const PowerOfTwoFrame& frame);
  const PowerOfTwoFrame& frame() const { return frame_; }

  // The primitive nearest to p, ties to the lowest id. `bound2`: a squared distance the caller knows the answer does
  // not exceed, which prunes the search; subtrees and primitives farther than it are skipped, so a bound below the
  // true distance gives primitive -1.
  NearestHit nearest(const Vec3& p, double bound2 = INFINITY) const;
  // The same answer, searched from primitive `seed` (a neighbour's nearest, or -1 for none): its distance is the
  // first bound, which is tight when the seed is the answer or nearly so, so the search visits few nodes.
  NearestHit nearestFrom(const Vec3& p, int64_t seed) const;

  // The subtrees a search from any point of a small region must open, found once for the region (a brick of a
  // dense field's cells): the tree's top levels are then walked once per region instead of once per point.
  class Frontier;
  // Fills `frontier` for the points within `radius` of `centre` whose nearest primitives are all at most `upper`
  // away: a subtree whose box is proven farther than `upper` from every such point is left out (it holds no
  // primitive a search would have compared equal or nearer), and the largest subtrees left are replaced by their
  // children while at most `maxEntries` (<= kMaxFrontier) remain. Without float pruning (a region beyond its
  // reach), the frontier is the root's children.
  void gather(const Vec3& centre, double radius, double upper, size_t maxEntries, Frontier& frontier) const;
  // nearestFrom for a point of the region `frontier` was gathered for: the same answer, bit for bit.
  NearestHit nearestFrom(const Vec3& p, int64_t seed, const Frontier& frontier) const;
  static constexpr size_t kMaxFrontier = 32;

  // The point of primitive `id` nearest to p.
  Vec3 closestPoint(int64_t id, const Vec3& p) const;

  size_t primitiveCount() const { return ids_.size(); }

 private:
  // Four children's oriented boxes in float, relative to origin_ (each holds every point of its primitives, about
  // its float centre along its float axes), as structure of arrays so that one SSE2 pass tests all four. A ray could
  // test the same boxes (a slab test in each box's axes, on the same lanes, its rounding bounded the same way): the
  // nodes carry nothing particular to points.
  struct alignas(16) WideNode {
    float centre[3][4];
    float axis[3][3][4];  // axis a's component i; orthonormal to float rounding
    float half[3][4];
    float magnitude[4];  // |centre|_1 plus the half extents: the size the rounding allowance scales with
    int32_t child[4];    // >= 0: a node; < 0: leaf ~child; unused lanes hold a box no point is near, masked out
    uint32_t count = 0;  // children in use
  };
  // A leaf's up to four primitives' lower bounds as float rows relative to origin_: the triangle's plane n.q = w, and
  // six outward half-planes of its own plane that hold it, e.q = ew: its edges' and, at each corner, the one whose
  // normal bisects the two edges' (in a corner's region of angle A the bound is then within cos((180 - A) / 4) of
  // the distance in the plane, where the edges alone give cos((180 - A) / 2)). The allowance k1 |q|_1 + k0 keeps each
  // below the exact double distance (nearest.cpp). Spheres, ellipsoids, needles and unused lanes hold zero rows: a
  // bound of 0 that prunes nothing.
  struct alignas(16) WideLeaf {
    float n[3][4], w[4];
    float e[6][3][4], ew[6][4];
    float k1[4], k0[4];
    uint32_t first = 0, count = 0;  // slots
  };
  struct BinaryNode {
    uint32_t first = 0;           // leaf: its first slot; inner: the second child (the first is the next node)
    uint32_t count = 0;           // primitives of a leaf; 0 for an inner node
    uint32_t begin = 0, end = 0;  // its slots
  };
  struct FloatBox {  // one child's lane of a WideNode
    float centre[3], axis[3][3], half[3];
  };
  double squaredDistanceTo(uint32_t slot, const Vec3& p, double bound2) const;
  // Lowers `best` to the nearest primitive under the children of nodes[0, count) (ties to the lowest id). `known`:
  // the slot of a primitive whose distance `best` already took into account (a seed), not computed again.
  static constexpr uint32_t kNoSlot = UINT32_MAX;
  void search(const Vec3& p, const WideNode* nodes, size_t count, NearestHit& best, uint32_t known = kNoSlot) const;
  // nearestFrom over the children of first[0, firstCount).
  NearestHit searchFrom(const Vec3& p, int64_t seed, const WideNode* first, size_t firstCount) const;
  void visitLeaf(const WideLeaf& leaf, const Vec3& p, const float (&q)[3], float qNorm, bool prune, float bestUp,
                 uint32_t known, NearestHit& best) const;
  uint32_t build(uint32_t begin, uint32_t end, const std::vector<Vec3>& centroids, std::vector<BinaryNode>& nodes);
  int32_t buildWide(uint32_t index, const std::vector<BinaryNode>& nodes, const std::vector<Box>& nodeBoxes,
                    const std::vector<FloatBox>& floatBoxes);
  FloatBox orientedBounds(const BinaryNode& node, const Scene& scene, const std::vector<Box>& boxes) const;
  WideLeaf makeLeaf(const BinaryNode& node) const;

  std::vector<WideNode> wide_;  // the root first
  std::vector<WideLeaf> leaves_;
  std::vector<uint32_t> ids_;               // slot -> primitive id, in leaf order
  std::vector<uint32_t> slotOf_;            // primitive id -> slot
  std::vector<Triangle> triangles_;         // by slot (unused slots of spheres hold nothing useful)
  std::vector<TriangleLowerBound> bounds_;  // by slot, of triangles
  std::vector<EllipsoidShape> shapes_;      // by sphere index
  Vec3 origin_{0, 0, 0};                    // the centre of the primitives' bounds: the float data's origin
  uint32_t triangleCount_ = 0;
  PowerOfTwoFrame frame_;
};

// Reused across regions by one thread: its nodes are the frontier's children, four to a node, copied lane by lane.
class NearestPrimitive::Frontier {
 private:
  friend class NearestPrimitive;
  std::vector<WideNode> nodes_;
};

}  // namespace vox
