// The bounded primitive nearest to any point (DESIGN.md "Distance and volume": Grid.distance, libvox.sdf): a
// bounding volume hierarchy over the scene's triangles, spheres and ellipsoids (planes are left out), queried depth
// first, nearer child first, pruned by proven lower bounds: each node's oriented box, each triangle's plane and edges
// (triangleLowerBound). Distances are the ones the --sdf band uses (squaredDistanceToTriangle,
// closestPointOnEllipsoid), so a dense field equals the band bit for bit.
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
  // Copies what it needs from `scene` (about 270 bytes per primitive, with the nodes). Throws InputError for a singular
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

  // The point of primitive `id` nearest to p.
  Vec3 closestPoint(int64_t id, const Vec3& p) const;

  size_t primitiveCount() const { return ids_.size(); }

  struct OrientedBox {
    Vec3 centre;
    std::array<Vec3, 3> axes;  // orthonormal to rounding
    Vec3 half;                 // half extents along the axes
  };

 private:
  struct Node {
    OrientedBox box;
    uint32_t first = 0;   // leaf: its first primitive slot; inner: the second child (the first is the next node)
    uint32_t count = 0;   // primitives of a leaf; 0 for an inner node
    uint32_t parent = 0;  // the root's is itself
  };
  double squaredDistanceTo(uint32_t slot, const Vec3& p, double bound2) const;
  void search(const Vec3& p, NearestHit& best, uint32_t root) const;
  void visitLeaf(const Node& leaf, const Vec3& p, NearestHit& best) const;
  uint32_t build(uint32_t begin, uint32_t end, const std::vector<Vec3>& centroids,
                 std::vector<std::array<uint32_t, 2>>& ranges, uint32_t parent);
  OrientedBox orientedBounds(uint32_t begin, uint32_t end, const Scene& scene, const std::vector<Box>& boxes) const;

  std::vector<Node> nodes_;
  std::vector<uint32_t> ids_;               // slot -> primitive id, in leaf order
  std::vector<uint32_t> slotOf_;            // primitive id -> slot
  std::vector<uint32_t> leafOf_;            // slot -> its leaf node
  std::vector<Triangle> triangles_;         // by slot (unused slots of spheres hold nothing useful)
  std::vector<TriangleLowerBound> bounds_;  // by slot, of triangles
  std::vector<EllipsoidShape> shapes_;      // by sphere index
  uint32_t triangleCount_ = 0;
  PowerOfTwoFrame frame_;
};

}  // namespace vox
