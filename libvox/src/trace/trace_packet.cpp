// Slice-by-slice packet traversal (trace_packet.h). Why it returns exactly what traceRay (and occluded) returns, for
// every ray:
// - The nearest hit of a ray lies in a cell the ray passes through, and (exact, sat, bbox grids) its primitive is in
//   that cell. Each slice's rectangle holds every cell of the slice that any still-walking ray of the packet can
//   touch: the rays' positions in the slab are bounded by interval arithmetic on a + c s (a, s per ray, c across
//   the slab), widened by the walker's positional tolerance and a bound on the rounding of that arithmetic.
// - Every primitive found there is tested with the same arithmetic as the scalar test (triangle_kernel.h) and kept
//   by the same order (closer()), so extra primitives change nothing: the minimum over a superset holding the
//   nearest hit is the nearest hit.
// - A ray stops walking after a slice when its best hit, widened by the walker's hit slack, lies before the next
//   slice's boundary, narrowed by the walker's exit slack: the stop rule of traceRay. An occlusion query stops a ray
//   at its first hit, as occluded() does; any hit the packet finds is a hit of that ray.
#include "vox/trace/trace_packet.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vox/core/cell_range.h"
#include "trace/mailbox.h"
#include "trace/triangle_kernel.h"
#include "vox/core/error.h"

namespace vox {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Largest slice rectangle, in cells per walking ray, worth visiting as a packet (a ray alone visits 1 to 3 cells
// per slice, each at several times the cost of a rectangle cell).
constexpr uint64_t kMaxCellsPerLane = 4;

// The rays of the packet that are still walking, as a structure of arrays, so that one triangle is tested against
// all of them in vector registers and the per-slice bookkeeping runs over contiguous data.
struct Lanes {
  static constexpr uint32_t N = kMaxPacketRays;
  // The ray, for the triangle kernel.
  alignas(64) double ox[N], oy[N], oz[N], dx[N], dy[N], dz[N], tMin[N], tMax[N];
  alignas(64) double t[N];  // result of the last test: the hit's t (valid where the hit bit is set)
  // The walk along the slice axis k: the ray crosses x_k = b at (b - ok) * invK; tolK is the walker's tolerance
  // there (RayAxes::tol[k]); the ray is done with slices entered after stopAt (the end of its walk, or its best
  // hit plus the hit slack).
  alignas(64) double ok[N], invK[N], tolK[N], stopAt[N], tEnd[N], hitSlack[N];
  // Position a + c s on the two other axes at slab coordinate c (relative to the packet's reference).
  alignas(64) double a[2][N], s[2][N];
  uint32_t ray[N];  // index of the lane's ray in the packet
  uint32_t count = 0;

  // The kernel runs over groups of four lanes: give the lanes past `count` in the last group defined values (a
  // removed lane keeps its old, defined values).
  void padTail() {
    for (uint32_t j = count; j < N && j % 4 != 0; ++j)
      for (double* v : {ox, oy, oz, dx, dy, dz, tMin, tMax}) v[j] = 0;
  }

  void remove(uint32_t j) {
    const uint32_t e = --count;
    for (double* v : {ox, oy, oz, dx, dy, dz, tMin, tMax, ok, invK, tolK, stopAt, tEnd, hitSlack}) v[j] = v[e];
    for (int q = 0; q < 2; ++q) a[q][j] = a[q][e], s[q][j] = s[q][e];
    ray[j] = ray[e];
  }
};

// One triangle against every lane, four at a time. Compiled twice, for AVX2 and for the baseline, and picked at
// load time: the arithmetic is IEEE double either way (no contraction), so both give the scalar test's t. Lanes past
// `count` hold zeros or retired rays (Lanes::padTail); their results are never read. Returns the lanes hit, as bits;
// lanes.t is meaningful only for those.
__attribute__((target_clones("avx2", "default"))) uint64_t triangleLanes(const TriangleData& tri, Lanes& lanes) {
  using kernel::Double4;
  const double v0[3] = {tri.v0.x, tri.v0.y, tri.v0.z}, e1[3] = {tri.e1.x, tri.e1.y, tri.e1.z},
               e2[3] = {tri.e2.x, tri.e2.y, tri.e2.z}, n[3] = {tri.n.x, tri.n.y, tri.n.z};
  uint64_t bits = 0;
  for (uint32_t j = 0; j < lanes.count; j += 4) {
    Double4 ox, oy, oz, dx, dy, dz, tMin, tMax, t;
    __builtin_memcpy(&ox, lanes.ox + j, sizeof(ox));
    __builtin_memcpy(&oy, lanes.oy + j, sizeof(oy));
    __builtin_memcpy(&oz, lanes.oz + j, sizeof(oz));
    __builtin_memcpy(&dx, lanes.dx + j, sizeof(dx));
    __builtin_memcpy(&dy, lanes.dy + j, sizeof(dy));
    __builtin_memcpy(&dz, lanes.dz + j, sizeof(dz));
    __builtin_memcpy(&tMin, lanes.tMin + j, sizeof(tMin));
    __builtin_memcpy(&tMax, lanes.tMax + j, sizeof(tMax));
    const auto hit = kernel::triangleHit(v0, e1, e2, n, ox, oy, oz, dx, dy, dz, tMin, tMax, t);
    __builtin_memcpy(lanes.t + j, &t, sizeof(t));
    bits |= uint64_t((hit[0] & 1) | (hit[1] & 2) | (hit[2] & 4) | (hit[3] & 8)) << j;
  }
  const uint64_t live = lanes.count == 64 ? ~uint64_t(0) : (uint64_t(1) << lanes.count) - 1;
  return bits & live;
}

// The axis along which the packet is sliced: the first ray's largest direction component, provided every ray is
// finite and travels the same way along it (1 / d_k a normal number) with a slope of at most 2 in the other axes.
// -1 when there is none (the rays are then traced one by one).
int sliceAxis(const Accel& accel, std::span<const Ray> rays) {
  const CellBoundaries& cb = accel.boundaries;
  if (accel.kind != AccelKind::Grid || rays.size() < 2 || cb.dims[0] == 0 || cb.dims[1] == 0 || cb.dims[2] == 0)
    return -1;
  const Vec3& d0 = rays[0].direction;
  int k = 0;
  if (std::fabs(d0.y) > std::fabs(d0[k])) k = 1;
  if (std::fabs(d0.z) > std::fabs(d0[k])) k = 2;
  const bool forward = d0[k] > 0;
  for (const Ray& ray : rays) {
    if (!isFinite(ray.origin) || !isFinite(ray.direction) || std::isnan(ray.tMin) || std::isnan(ray.tMax)) return -1;
    const double dk = ray.direction[k];
    if (!std::isnormal(1.0 / dk) || (dk > 0) != forward) return -1;
    const double other = std::max(std::fabs(ray.direction[(k + 1) % 3]), std::fabs(ray.direction[(k + 2) % 3]));
    if (!(std::fabs(dk) >= 0.5 * other)) return -1;
  }
  return k;
}

// Where the rays of the packet can be on one of the other axes while crossing a slab: every ray is a + c s there
// (c the slab coordinate relative to the packet's reference, a and s per ray), so an interval bound over the rays
// and over c in the slab bounds them all.
struct AxisBounds {
  double aLo = 0, aHi = 0, sLo = 0, sHi = 0;
  double magnitude = 0;  // largest |a| + |o| + |c0 - o_k| |s| of any ray: scales the rounding of a and of a + c s
  double sMax = 0;       // largest |s|
  double tolPos = 0;     // the walker's positional tolerance on this axis, for the largest origin coordinate

  // The cells of this axis that the rays can touch for c in [cA, cB] (relative to the reference).
  std::array<int64_t, 3> cells(const CellBoundaries& cb, int axis, double cA, double cB) const {
    const double p0 = cA * sLo, p1 = cA * sHi, p2 = cB * sLo, p3 = cB * sHi;
    const double lo = aLo + std::min({p0, p1, p2, p3}), hi = aHi + std::max({p0, p1, p2, p3});
    const double pad = tolPos + 64 * kEps * (magnitude + std::max(std::fabs(cA), std::fabs(cB)) * sMax);
    const double* b = cb.b[axis].data();
    const auto r = cellRangeOnAxis(
        int64_t(cb.dims[axis]), cb.cellsPerUnit[axis], [b](int64_t i) { return b[i]; }, lo - pad, hi + pad);
    return {r[0], r[1], 0};
  }

  // Whether the point at slab coordinate c (relative to the reference) and position p on this axis lies below every
  // ray by more than the tolerance (-1), above every ray (+1), or neither (0). "Below" is the region under the
  // concave bound aLo + min(c sLo, c sHi), a convex set, and "above" the region over the convex bound: a triangle
  // whose three vertices are all below (or all above) lies there whole, and no ray of the packet can meet it.
  int side(double c, double p) const {
    const double pad = tolPos + 64 * kEps * (magnitude + std::fabs(c) * sMax + std::fabs(p));
    const double cLo = c * sLo, cHi = c * sHi;
    if (p < aLo + std::min(cLo, cHi) - pad) return -1;
    if (p > aHi + std::max(cLo, cHi) + pad) return 1;
    return 0;
  }
};

// Frustum culling of a triangle against the packet (Wald et al. 2006): true when, on one of the two axes across the
// slices, all three vertices lie on the same outer side of every ray.
bool outsidePacket(const TriangleData& tri, int k, const int other[2], double c0, const AxisBounds bounds[2]) {
  const Vec3 v[3] = {tri.v0, tri.v0 + tri.e1, tri.v0 + tri.e2};
  for (int q = 0; q < 2; ++q) {
    const int u = other[q];
    const int s0 = bounds[q].side(v[0][k] - c0, v[0][u]);
    if (s0 != 0 && bounds[q].side(v[1][k] - c0, v[1][u]) == s0 && bounds[q].side(v[2][k] - c0, v[2][u]) == s0)
      return true;
  }
  return false;
}

// Whether every block of the two-level table in the layer of blocks holding `slice` (slice axis k) and in the cell
// ranges ru x rv of the other axes is empty; false for a wide rectangle, which is not worth the look.
bool allBlocksEmpty(const Accel& accel, int k, const int other[2], int64_t slice, const std::array<int64_t, 3>& ru,
                    const std::array<int64_t, 3>& rv) {
  if (ru[0] > ru[1] || rv[0] > rv[1]) return true;
  const uint32_t s = accel.blockShift;
  const int64_t u0 = ru[0] >> s, u1 = ru[1] >> s, v0 = rv[0] >> s, v1 = rv[1] >> s;
  if ((u1 - u0 + 1) * (v1 - v0 + 1) > 16) return false;
  uint64_t b[3];
  b[k] = uint64_t(slice) >> s;
  for (int64_t v = v0; v <= v1; ++v)
    for (int64_t u = u0; u <= u1; ++u) {
      b[other[0]] = uint64_t(u), b[other[1]] = uint64_t(v);
      if (accel.blockSlot[b[0] + accel.blockDims[0] * (b[1] + uint64_t(accel.blockDims[1]) * b[2])] != kEmptyCell)
        return false;
    }
  return true;
}

// What a packet asks of each ray: its nearest hit (traceRay), or whether anything is hit at all (occluded).
enum class Query : uint8_t { Nearest, Any };

// The answer of the single-ray query; for Query::Any, a valid Hit (prim 0) stands for "occluded".
Hit alone(const Accel& accel, const Ray& ray, Query query, TraceStats* stats) {
  if (query == Query::Nearest) return traceRay(accel, ray, stats);
  return occluded(accel, ray, stats) ? Hit{0, 0} : Hit{};
}

// One packet's traversal along slice axis k: the rays, the lanes of those still walking, their best hits so far
// (best[r] for ray r) and the counters. Lanes are not zeroed: 10 KB per packet would cost more than a packet's
// slices; see Lanes::padTail().
struct Packet {
  Packet(const Accel& accel_, std::span<const Ray> rays_, int k_, Query query_)
      : accel(accel_),
        cb(accel_.boundaries),
        rays(rays_),
        k(k_),
        other{(k_ + 1) % 3, (k_ + 2) % 3},
        query(query_),
        forward(rays_[0].direction[k_] > 0),
        c0(rays_[0].origin[k_]),
        bk(cb.b[k_].data()),
        nk(cb.dims[k_]) {
    st.rays = rays_.size();
  }
  const Accel& accel;
  const CellBoundaries& cb;
  std::span<const Ray> rays;
  const int k, other[2];
  const Query query;
  const bool forward;
  const double c0;  // slab coordinates are relative to the first ray's origin on k
  const double* const bk;
  const int64_t nk;
  TraceStats st;
  Hit best[kMaxPacketRays];
  Lanes lanes;
  AxisBounds bounds[2];

  bool any() const { return query == Query::Any; }
};

// Tests ray r against the primitives every ray tests (planes, outside primitives) into p.best[r]; true when that
// answers an occlusion query already.
bool testAlwaysTested(Packet& p, uint32_t r) {
  const Ray& ray = p.rays[r];
  p.best[r] = Hit{};
  for (uint32_t id : p.accel.alwaysTested) {
    double t;
    ++p.st.tests;
    if (intersectPrimitive(p.accel, id, ray, t) && closer(t, id, p.best[r])) {
      p.best[r] = {t, id};
      if (p.any()) break;
    }
  }
  return p.any() && p.best[r].valid();
}

// What the lanes cover: the span of slab coordinates within [tMin, tEnd] and the largest origin coordinates.
struct LaneSpan {
  double pLo = kInfinity, pHi = -kInfinity;
  double originMax[3] = {0, 0, 0};
};

// Gives ray r a lane, unless it passes beside the grid box (its a + c s stays off the grid's range on some axis over
// the grid's slab range; the margin covers the rounding, as in AxisBounds::cells).
void addLane(Packet& p, uint32_t r, LaneSpan& span) {
  const Ray& ray = p.rays[r];
  const CellBoundaries& cb = p.cb;
  const int k = p.k;
  const double dk = ray.direction[k], ok = ray.origin[k];
  const double invK = 1.0 / dk, absInv = std::fabs(invK);
  const double shift = p.c0 - ok, cGridLo = p.bk[0] - p.c0, cGridHi = p.bk[p.nk] - p.c0;
  double slope[2], at[2];
  for (int q = 0; q < 2; ++q) {
    const int u = p.other[q];
    slope[q] = ray.direction[u] * invK;
    at[q] = ray.origin[u] + shift * slope[q];
    const double p0 = at[q] + cGridLo * slope[q], p1 = at[q] + cGridHi * slope[q];
    const double reach = std::max(std::fabs(cGridLo), std::fabs(cGridHi)) * std::fabs(slope[q]);
    const double margin =
        positionTolerance(cb, u, std::fabs(at[q]) + std::fabs(ray.origin[u]) + std::fabs(shift * slope[q]) + reach);
    if (std::max(p0, p1) < cb.b[u].front() - margin || std::min(p0, p1) > cb.b[u].back() + margin) return;
  }
  Lanes& lanes = p.lanes;
  const uint32_t l = lanes.count++;
  lanes.ray[l] = r;
  lanes.ox[l] = ray.origin.x, lanes.oy[l] = ray.origin.y, lanes.oz[l] = ray.origin.z;
  lanes.dx[l] = ray.direction.x, lanes.dy[l] = ray.direction.y, lanes.dz[l] = ray.direction.z;
  lanes.tMin[l] = ray.tMin, lanes.tMax[l] = ray.tMax;
  lanes.ok[l] = ok;
  lanes.invK[l] = invK;
  lanes.tolK[l] = positionTolerance(cb, k, ok) * absInv;
  // At least RayAxes::hitSlack: divided by |d_k| instead of the largest |d|.
  const double hitSlack = hitSlackLength(cb, ray.origin) * absInv;
  const double tEnd = ray.tMax + hitSlackAt(hitSlack, ray.tMax);  // the walker's last parameter
  lanes.hitSlack[l] = hitSlack;
  lanes.tEnd[l] = tEnd;
  const Hit& best = p.best[r];
  lanes.stopAt[l] = best.valid() ? std::min(tEnd, best.t + hitSlackAt(hitSlack, best.t)) : tEnd;
  const double pStart = ok + ray.tMin * dk, pEnd = ok + tEnd * dk;
  span.pLo = std::min({span.pLo, pStart, pEnd});
  span.pHi = std::max({span.pHi, pStart, pEnd});
  for (double pos : {pStart, pEnd})
    if (std::isfinite(pos)) span.originMax[k] = std::max(span.originMax[k], std::fabs(pos));
  for (int q = 0; q < 2; ++q) {
    const int u = p.other[q];
    AxisBounds& ab = p.bounds[q];
    lanes.s[q][l] = slope[q];
    lanes.a[q][l] = at[q];
    ab.magnitude =
        std::max(ab.magnitude, std::fabs(at[q]) + std::fabs(ray.origin[u]) + std::fabs(shift) * std::fabs(slope[q]));
    ab.sMax = std::max(ab.sMax, std::fabs(slope[q]));
    span.originMax[u] = std::max(span.originMax[u], std::fabs(ray.origin[u]));
  }
}

// The interval bounds of the walking lanes' a and s on both axes.
void refreshBounds(Packet& p) {
  const Lanes& lanes = p.lanes;
  for (int q = 0; q < 2; ++q) {
    AxisBounds& ab = p.bounds[q];
    ab.aLo = ab.aHi = lanes.a[q][0];
    ab.sLo = ab.sHi = lanes.s[q][0];
    for (uint32_t j = 1; j < lanes.count; ++j) {
      ab.aLo = std::min(ab.aLo, lanes.a[q][j]), ab.aHi = std::max(ab.aHi, lanes.a[q][j]);
      ab.sLo = std::min(ab.sLo, lanes.s[q][j]), ab.sHi = std::max(ab.sHi, lanes.s[q][j]);
    }
  }
}

// Keeps the hits in `hitBits` (lanes, with their t in lanes.t) of primitive `id` that are closer than the lanes'
// best; a lane with a new best stops after the slice in which its walk could still find a nearer one (an occlusion
// query's lane after this slice).
void recordHits(Packet& p, uint32_t id, uint64_t hitBits) {
  Lanes& lanes = p.lanes;
  for (; hitBits != 0; hitBits &= hitBits - 1) {
    const uint32_t l = uint32_t(__builtin_ctzll(hitBits));
    Hit& h = p.best[lanes.ray[l]];
    const double t = lanes.t[l];
    if (closer(t, id, h)) {
      h = {t, id};
      const double limit = t + hitSlackAt(lanes.hitSlack[l], t);
      lanes.stopAt[l] = p.any() ? -kInfinity : std::min(lanes.tEnd[l], limit);
    }
  }
}

// Tests the primitives of the cells ru x rv of `slice` (each once per packet, through the mailbox) against the
// walking lanes; triangles the packet's frustum misses are skipped.
void testCells(Packet& p, int64_t slice, const std::array<int64_t, 3>& ru, const std::array<int64_t, 3>& rv,
               Mailbox<512>& mailbox) {
  const Accel& accel = p.accel;
  Lanes& lanes = p.lanes;
  uint32_t idx[3];
  idx[p.k] = uint32_t(slice);
  for (int64_t j = rv[0]; j <= rv[1]; ++j) {
    idx[p.other[1]] = uint32_t(j);
    for (int64_t i = ru[0]; i <= ru[1]; ++i) {
      idx[p.other[0]] = uint32_t(i);
      ++p.st.cells;
      const uint32_t c = accel.lookup(idx[0], idx[1], idx[2]);
      if (c >= kSolidCell) continue;
      const uint64_t end = accel.grid->cellStart[c + 1];
      for (uint64_t ref = accel.grid->cellStart[c]; ref < end; ++ref) {
        const uint32_t id = accel.grid->primIds[ref];
        if (mailbox.seen(id)) {
          p.st.mailboxSkips += lanes.count;
          continue;
        }
        uint64_t hitBits = 0;
        if (id < accel.triangleCount) {
          const TriangleData& tri = cellTriangle(accel, ref, id);
          if (outsidePacket(tri, p.k, p.other, p.c0, p.bounds)) continue;
          p.st.tests += lanes.count;
          hitBits = triangleLanes(tri, lanes);
        } else {
          p.st.tests += lanes.count;
          for (uint32_t l = 0; l < lanes.count; ++l)
            if (intersectPrimitive(accel, id, p.rays[lanes.ray[l]], lanes.t[l])) hitBits |= uint64_t(1) << l;
        }
        recordHits(p, id, hitBits);
      }
    }
  }
}

// Retires the lanes that cannot meet anything nearer in the slices after `slice` (the stop rule of traceRay: the
// best hit plus its slack lies before the next slice's boundary minus the exit slack), or whose walk ends before
// them; true when any was retired.
bool retireLanes(Packet& p, int64_t slice) {
  Lanes& lanes = p.lanes;
  const double boundary = p.forward ? p.bk[slice + 1] : p.bk[slice];
  uint64_t retire = 0;
  for (uint32_t l = 0; l < lanes.count; ++l) {
    const double tCross = (boundary - lanes.ok[l]) * lanes.invK[l];
    const double tNextMin = tCross - (lanes.tolK[l] + kWalkRel * std::fabs(tCross));
    retire |= uint64_t(lanes.stopAt[l] < tNextMin) << l;
  }
  if (retire == 0) return false;
  // Highest first: remove() moves the last lane into the freed one, and lanes above were already handled.
  while (retire != 0) {
    const uint32_t l = uint32_t(63 - __builtin_clzll(retire));
    lanes.remove(l);
    retire &= ~(uint64_t(1) << l);
  }
  return true;
}

// The last slice (in the order of travel, at most `last`) of the layer of blocks (Accel::blockSlot) holding `slice`.
int64_t layerEnd(const Packet& p, int64_t slice, int64_t last) {
  const int64_t blockMask = (int64_t(1) << p.accel.blockShift) - 1;
  return p.forward ? std::min(slice | blockMask, last) : std::max(slice & ~blockMask, last);
}

// Whether every block that the packet can touch in the slices from `slice` to `end` is empty.
bool layerEmpty(const Packet& p, int64_t slice, int64_t end) {
  const double cA = p.bk[p.forward ? slice : slice + 1] - p.c0, cB = p.bk[p.forward ? end + 1 : end] - p.c0;
  const auto ru = p.bounds[0].cells(p.cb, p.other[0], cA, cB);
  const auto rv = p.bounds[1].cells(p.cb, p.other[1], cA, cB);
  return allBlocksEmpty(p.accel, p.k, p.other, slice, ru, rv);
}

// The walk over the slices `first` to `last` of the lanes' rays, until no lane walks.
void walkSlices(Packet& p, int64_t first, int64_t last) {
  Lanes& lanes = p.lanes;
  Mailbox<512> mailbox;  // per packet: more primitives than one ray meets
  bool boundsStale = true;
  const int64_t step = p.forward ? 1 : -1;
  // The slices up to this one (in the order of travel) lie in a layer of blocks already found not empty.
  int64_t checkedUpTo = first - step;
  for (int64_t slice = first; lanes.count > 0; slice += step) {
    if (boundsStale) refreshBounds(p);
    boundsStale = false;
    // Empty-space skipping: the rest of an empty layer of blocks in one step.
    if (p.accel.blockShift != 0 && (p.forward ? slice > checkedUpTo : slice < checkedUpTo)) {
      const int64_t end = layerEnd(p, slice, last);
      if (layerEmpty(p, slice, end)) {
        if (end == last) break;
        slice = end;
        continue;
      }
      checkedUpTo = end;
    }
    const double cA = p.bk[slice] - p.c0, cB = p.bk[slice + 1] - p.c0;
    const auto ru = p.bounds[0].cells(p.cb, p.other[0], cA, cB);
    const auto rv = p.bounds[1].cells(p.cb, p.other[1], cA, cB);
    if (ru[0] > ru[1] || rv[0] > rv[1]) {
      // Nothing here: has the packet left the grid for good?
      const double cEnd = (p.forward ? p.bk[last + 1] : p.bk[last]) - p.c0;
      const auto restU = p.bounds[0].cells(p.cb, p.other[0], cA, cEnd);
      const auto restV = p.bounds[1].cells(p.cb, p.other[1], cA, cEnd);
      if (restU[0] > restU[1] || restV[0] > restV[1]) break;
    }
    // A packet wide compared with the cells (a large grid, a wide tile, rays diverging far from the camera) would
    // visit more cells per slice than its rays walking alone: let them walk alone from here. traceRay starts each
    // ray afresh, so its answer is the same whatever this packet found so far.
    if (ru[0] <= ru[1] && rv[0] <= rv[1] &&
        uint64_t(ru[1] - ru[0] + 1) * uint64_t(rv[1] - rv[0] + 1) > kMaxCellsPerLane * lanes.count + 8) {
      for (uint32_t l = 0; l < lanes.count; ++l)
        p.best[lanes.ray[l]] = alone(p.accel, p.rays[lanes.ray[l]], p.query, &p.st);
      p.st.rays -= lanes.count;
      break;
    }
    testCells(p, slice, ru, rv, mailbox);
    if (slice == last) break;
    boundsStale = retireLanes(p, slice);
  }
}

// Up to kMaxPacketRays rays. For Query::Any a ray stops at its first hit, and hits[r] is valid exactly when the ray
// is occluded.
void tracePacketChunk(const Accel& accel, std::span<const Ray> rays, std::span<Hit> hits, Query query,
                      TraceStats* stats) {
  const int k = sliceAxis(accel, rays);
  if (k < 0) {
    for (size_t r = 0; r < rays.size(); ++r) hits[r] = alone(accel, rays[r], query, stats);
    return;
  }
  Packet p(accel, rays, k, query);
  LaneSpan span;
  for (uint32_t r = 0; r < rays.size(); ++r)
    if (!testAlwaysTested(p, r)) addLane(p, r, span);  // an occluded ray needs no lane
  for (int q = 0; q < 2; ++q) p.bounds[q].tolPos = positionTolerance(p.cb, p.other[q], span.originMax[p.other[q]]);
  // Slices to walk, in order of travel: from `first` to `last`.
  const double padK = positionTolerance(p.cb, k, span.originMax[k]);
  const double* bk = p.bk;
  const auto range = cellRangeOnAxis(
      p.nk, p.cb.cellsPerUnit[k], [bk](int64_t i) { return bk[i]; }, span.pLo - padK, span.pHi + padK);
  if (range[0] <= range[1] && p.lanes.count > 0) {
    p.lanes.padTail();
    walkSlices(p, p.forward ? range[0] : range[1], p.forward ? range[1] : range[0]);
  }
  for (uint32_t r = 0; r < rays.size(); ++r) hits[r] = p.best[r];
  if (stats) *stats += p.st;
}

}  // namespace

void tracePacket(const Accel& accel, std::span<const Ray> rays, std::span<Hit> hits, TraceStats* stats) {
  if (hits.size() < rays.size()) fail<Error>("tracePacket: ", rays.size(), " rays but room for ", hits.size(), " hits");
  for (size_t begin = 0; begin < rays.size(); begin += kMaxPacketRays) {
    const size_t count = std::min<size_t>(kMaxPacketRays, rays.size() - begin);
    tracePacketChunk(accel, rays.subspan(begin, count), hits.subspan(begin, count), Query::Nearest, stats);
  }
}

void occludedPacket(const Accel& accel, std::span<const Ray> rays, std::span<bool> occluded, TraceStats* stats) {
  if (occluded.size() < rays.size())
    fail<Error>("occludedPacket: ", rays.size(), " rays but room for ", occluded.size(), " answers");
  Hit hits[kMaxPacketRays];
  for (size_t begin = 0; begin < rays.size(); begin += kMaxPacketRays) {
    const size_t count = std::min<size_t>(kMaxPacketRays, rays.size() - begin);
    tracePacketChunk(accel, rays.subspan(begin, count), {hits, count}, Query::Any, stats);
    for (size_t i = 0; i < count; ++i) occluded[begin + i] = hits[i].valid();
  }
}

}  // namespace vox
