// The level set of the signed-distance band as a closed 2-manifold (level_surface.h), by marching tetrahedra over
// the Freudenthal triangulation of the lattice of cell centres.
//
// Why tetrahedra and not a marching-cubes table: the level set of a piecewise-linear function over a triangulation
// of R^3, with no vertex exactly on the level, is a closed 2-manifold (each point of it lies in the interior of an
// edge of the triangulation or of a face or tetrahedron, and the tetrahedra around an edge form one cycle, so the
// triangles around a vertex form one fan). The Freudenthal (Kuhn) triangulation is the same in every cube (each
// square face is split along the diagonal from its low to its high corner), so neighbouring cubes agree on every
// shared face with no ambiguity rule at all; a marching-cubes table needs one (Chernyaev's 33 cases) to be closed.
// Ties are broken by "inside means d < level", so no vertex lies on the level. The cost is more, thinner
// triangles (about twice marching cubes').
//
// Which cubes: every cube of the lattice padded by one point whose corners are not all on one side, found row by
// row (four rows of cells at once, level_surface.h says how centres outside the band get a side). For a continuous
// field and |level| <= HALF h - D those are exactly the cubes with all 8 centres in the band and the cubes closing
// the surface on the grid's bounds, but marching whatever the sides say keeps the output closed for any band,
// including the jumps of an open mesh's sign.
#include "vox/export/level_surface.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "vox/core/error.h"
#include "voxel_surface.h"

namespace vox {
namespace level_surface_impl {

// Cube corner c = bx | by << 1 | bz << 2. A Freudenthal edge joins corners ca, cb with ca a subset of cb (as bits):
// its lower end is ca, its direction cb ^ ca (1..7).
struct TetTriangle {
  std::array<std::array<uint8_t, 2>, 3> edges;  // (lower corner, upper corner) per vertex
};
struct TetCase {
  uint8_t count = 0;  // 0, 1 (a triangle) or 2 (a quad, cyclic edges q0..q3, split at run time)
  std::array<std::array<uint8_t, 2>, 4> quad{};
};

// The 6 tetrahedra of the cube (one per order of the axes) and, for each of the 16 inside patterns of their
// corners, the oriented triangle or quad. Orientation is decided on the midpoints of the edges (doubled, so small
// integers, exact): the normal must point to an outside corner. Moving vertices along their edges never flattens a
// triangle (three points inside three edges of a tetrahedron are never collinear), so the orientation holds for
// any interpolation.
struct Tables {
  std::array<std::array<uint8_t, 4>, 6> tets{};
  std::array<std::array<TetCase, 16>, 6> cases{};
};

using I3 = std::array<int, 3>;
I3 twiceMidpoint(uint8_t a, uint8_t b) {
  return {(a & 1) + (b & 1), ((a >> 1) & 1) + ((b >> 1) & 1), ((a >> 2) & 1) + ((b >> 2) & 1)};
}
// Whether the triangle's normal ((m1 - m0) x (m2 - m0)) points towards corner `out`.
bool facesCorner(const std::array<std::array<uint8_t, 2>, 3>& e, uint8_t out) {
  const I3 m0 = twiceMidpoint(e[0][0], e[0][1]), m1 = twiceMidpoint(e[1][0], e[1][1]),
           m2 = twiceMidpoint(e[2][0], e[2][1]);
  const I3 u{m1[0] - m0[0], m1[1] - m0[1], m1[2] - m0[2]}, v{m2[0] - m0[0], m2[1] - m0[1], m2[2] - m0[2]};
  const I3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const I3 p{2 * (out & 1) - m0[0], 2 * ((out >> 1) & 1) - m0[1], 2 * ((out >> 2) & 1) - m0[2]};
  const int dot = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
  VOX_CHECK(dot != 0);
  return dot > 0;
}
std::array<uint8_t, 2> edgeOf(uint8_t a, uint8_t b) {
  return (a & b) == a ? std::array<uint8_t, 2>{a, b} : std::array<uint8_t, 2>{b, a};
}

Tables makeTables() {
  Tables t;
  const int orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < 6; ++k) {
    const uint8_t v1 = uint8_t(1 << orders[k][0]), v2 = uint8_t(v1 | (1 << orders[k][1]));
    t.tets[k] = {0, v1, v2, 7};
    for (int pattern = 1; pattern < 15; ++pattern) {
      std::vector<uint8_t> in, out;
      for (int v = 0; v < 4; ++v) (pattern >> v & 1 ? in : out).push_back(t.tets[k][v]);
      TetCase& c = t.cases[k][pattern];
      if (in.size() == 1 || out.size() == 1) {
        const bool lone = in.size() == 1;  // the lone corner and the three others
        const uint8_t a = lone ? in[0] : out[0];
        const std::vector<uint8_t>& rest = lone ? out : in;
        std::array<std::array<uint8_t, 2>, 3> e{edgeOf(a, rest[0]), edgeOf(a, rest[1]), edgeOf(a, rest[2])};
        if (!facesCorner(e, out[0])) std::swap(e[1], e[2]);
        c.count = 1;
        c.quad = {e[0], e[1], e[2], e[2]};
      } else {
        // Inside a, b; outside c, d: the quad (a,c) (a,d) (b,d) (b,c) is a cycle (consecutive edges share a corner).
        std::array<std::array<uint8_t, 2>, 4> q{edgeOf(in[0], out[0]), edgeOf(in[0], out[1]), edgeOf(in[1], out[1]),
                                                edgeOf(in[1], out[0])};
        if (!facesCorner({q[0], q[1], q[2]}, out[0])) std::swap(q[1], q[3]);
        c.count = 2;
        c.quad = q;
      }
    }
  }
  return t;
}

const Tables& tables() {
  static const Tables t = makeTables();
  return t;
}

// A lattice edge: its lower end as an index of the lattice padded by one point on every side (so points beyond the
// grid have keys too; the padded lattice can exceed 2^61 points, hence not packed with the direction), and its
// direction bits.
struct EdgeId {
  uint64_t point = 0;
  uint64_t dir = 0;
  friend bool operator<(const EdgeId& a, const EdgeId& b) {
    return a.point != b.point ? a.point < b.point : a.dir < b.dir;
  }
  friend bool operator==(const EdgeId& a, const EdgeId& b) = default;
};

enum class Kind : uint8_t { Band, OutsideBand, BeyondGrid };
struct Corner {
  Kind kind = Kind::BeyondGrid;
  bool inside = false;
  double value = 0;  // the distance, for Band
};

// The band by rows: rowStart[r] .. rowStart[r + 1] are the band indices of row r = j + ny * k (keys / nx), and
// rowSide the side of the row's first cell (i = 0) for every row, band or not.
class Band {
 public:
  Band(const Grid& grid, double level) : grid_(grid), level_(level), n_(grid.dims) {
    const uint64_t rows = uint64_t(n_[1]) * n_[2];
    rowStart_.assign(rows + 1, 0);
    for (uint64_t key : grid.sdfKeys) ++rowStart_[key / n_[0] + 1];
    for (uint64_t r = 0; r < rows; ++r) rowStart_[r + 1] += rowStart_[r];
    computeRowSides();
  }

  // The corner at lattice point (i, j, k), which may lie one point beyond the grid on any axis.
  Corner at(int64_t i, int64_t j, int64_t k) const {
    if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2]) return {};
    const uint64_t row = uint64_t(j) + uint64_t(n_[1]) * uint64_t(k);
    const uint64_t key = uint64_t(i) + uint64_t(n_[0]) * row;
    const auto begin = grid_.sdfKeys.begin() + ptrdiff_t(rowStart_[row]);
    const auto end = grid_.sdfKeys.begin() + ptrdiff_t(rowStart_[row + 1]);
    if (begin == end) return {Kind::OutsideBand, rowInside_[row] != 0, 0};
    const auto it = std::lower_bound(begin, end, key);
    if (it != end && *it == key) return band(size_t(it - grid_.sdfKeys.begin()));
    // The band cell before it in the row, or else the one after it.
    const size_t nearest = size_t((it == begin ? it : it - 1) - grid_.sdfKeys.begin());
    return {Kind::OutsideBand, grid_.sdfValues[nearest] < level_, 0};
  }
  Corner band(size_t index) const {
    const double v = grid_.sdfValues[index];
    return {Kind::Band, v < level_, v};
  }
  uint64_t rowBegin(uint64_t row) const { return rowStart_[row]; }
  uint64_t rowEnd(uint64_t row) const { return rowStart_[row + 1]; }

  // at(i, j, k) for one row (j, k) and i never decreasing from call to call: a position that only moves forward
  // instead of a binary search per corner (the same answers: the first band cell at or after i, as lower_bound).
  class RowCursor {
   public:
    RowCursor(const Band& band, int64_t j, int64_t k) : band_(band) {
      const auto& n = band.n_;
      if (j < 0 || k < 0 || j >= n[1] || k >= n[2]) return;  // beyond the grid: every corner BeyondGrid
      inGrid_ = true;
      row_ = uint64_t(j) + uint64_t(n[1]) * uint64_t(k);
      pos_ = begin_ = band.rowStart_[row_];
      end_ = band.rowStart_[row_ + 1];
    }
    Corner at(int64_t i) {
      const auto& n = band_.n_;
      if (!inGrid_ || i < 0 || i >= n[0]) return {};
      if (begin_ == end_) return {Kind::OutsideBand, band_.rowInside_[row_] != 0, 0};
      const uint64_t key = uint64_t(i) + uint64_t(n[0]) * row_;
      const auto& keys = band_.grid_.sdfKeys;
      while (pos_ < end_ && keys[pos_] < key) ++pos_;
      if (pos_ < end_ && keys[pos_] == key) return band_.band(pos_);
      const uint64_t nearest = pos_ == begin_ ? pos_ : pos_ - 1;
      return {Kind::OutsideBand, band_.grid_.sdfValues[nearest] < band_.level_, 0};
    }

   private:
    const Band& band_;
    bool inGrid_ = false;
    uint64_t row_ = 0, begin_ = 0, end_ = 0, pos_ = 0;
  };

 private:
  // Rows without band cells take the side of a neighbouring row (j +- 1 or k +- 1), breadth first from the rows
  // with band cells; with no band at all everything is outside.
  void computeRowSides() {
    const uint64_t rows = uint64_t(n_[1]) * n_[2];
    rowInside_.assign(rows, 0);
    std::vector<uint8_t> known(rows, 0);
    std::deque<uint64_t> queue;
    for (uint64_t r = 0; r < rows; ++r) {
      if (rowStart_[r] == rowStart_[r + 1]) continue;
      known[r] = 1;
      rowInside_[r] = grid_.sdfValues[rowStart_[r]] < level_;
      queue.push_back(r);
    }
    while (!queue.empty()) {
      const uint64_t r = queue.front();
      queue.pop_front();
      const uint64_t j = r % n_[1], k = r / n_[1];
      const auto visit = [&](uint64_t s) {
        if (known[s]) return;
        known[s] = 1;
        rowInside_[s] = rowInside_[r];
        queue.push_back(s);
      };
      if (j > 0) visit(r - 1);
      if (j + 1 < n_[1]) visit(r + 1);
      if (k > 0) visit(r - n_[1]);
      if (k + 1 < n_[2]) visit(r + n_[1]);
    }
  }

  const Grid& grid_;
  double level_;
  std::array<uint32_t, 3> n_;
  std::vector<uint64_t> rowStart_;
  std::vector<uint8_t> rowInside_;
};

// Collects the triangles of the cubes as triples of lattice edges.
class Marcher {
 public:
  explicit Marcher(const Grid& grid) : n_(grid.dims) {}

  // The cube with lowest corner m (padded lattice: m may be -1 on any axis); corners in cube order.
  void march(const std::array<int64_t, 3>& m, const std::array<Corner, 8>& c, const Grid& grid, double level) {
    const Tables& t = tables();
    for (int k = 0; k < 6; ++k) {
      int pattern = 0;
      for (int v = 0; v < 4; ++v) pattern |= int(c[t.tets[k][v]].inside) << v;
      const TetCase& tc = t.cases[k][pattern];
      if (tc.count == 0) continue;
      std::array<EdgeId, 4> e;
      for (int v = 0; v < 4; ++v) e[v] = edgeId(m, tc.quad[v][0], tc.quad[v][1]);
      if (tc.count == 1) {
        triangles.push_back({e[0], e[1], e[2]});
        continue;
      }
      // Split the quad along its shorter diagonal (better shaped triangles; either split is closed and manifold).
      const auto pos = [&](int v) { return position(m, tc.quad[v][0], tc.quad[v][1], c, grid, level); };
      const Vec3 p0 = pos(0), p1 = pos(1), p2 = pos(2), p3 = pos(3);
      if (squaredLength(p2 - p0) <= squaredLength(p3 - p1)) {
        triangles.push_back({e[0], e[1], e[2]});
        triangles.push_back({e[0], e[2], e[3]});
      } else {
        triangles.push_back({e[0], e[1], e[3]});
        triangles.push_back({e[1], e[2], e[3]});
      }
    }
  }

  // The vertex on the edge between corners a (lower) and b of the cube at m: interpolated between band values,
  // halfway otherwise (the closing cap, on the grid's bounds).
  Vec3 position(const std::array<int64_t, 3>& m, uint8_t a, uint8_t b, const std::array<Corner, 8>& c, const Grid& grid,
                double level) const {
    double t = 0.5;
    if (c[a].kind == Kind::Band && c[b].kind == Kind::Band) {
      t = (level - c[a].value) / (c[b].value - c[a].value);
      t = std::clamp(t, kMinT, 1 - kMinT);
    }
    Vec3 p;
    for (int axis = 0; axis < 3; ++axis) {
      const double pa = cellCentreOnAxis(grid.bounds, grid.dims, axis, m[axis] + ((a >> axis) & 1));
      const double pb = cellCentreOnAxis(grid.bounds, grid.dims, axis, m[axis] + ((b >> axis) & 1));
      p.at(axis) = pa == pb ? pa : pa + t * (pb - pa);
    }
    return p;
  }

  EdgeId edgeId(const std::array<int64_t, 3>& m, uint8_t lower, uint8_t upper) const {
    const uint64_t i = uint64_t(m[0] + 1 + (lower & 1)), j = uint64_t(m[1] + 1 + ((lower >> 1) & 1)),
                   k = uint64_t(m[2] + 1 + ((lower >> 2) & 1));
    return {i + (uint64_t(n_[0]) + 2) * (j + (uint64_t(n_[1]) + 2) * k), uint64_t(upper ^ lower)};
  }
  // The lowest corner of the cube an edge id came from is not needed: the edge's own lower end and direction.
  std::array<int64_t, 3> lowerEnd(const EdgeId& e) const {
    const uint64_t nx = uint64_t(n_[0]) + 2, ny = uint64_t(n_[1]) + 2;
    return {int64_t(e.point % nx) - 1, int64_t((e.point / nx) % ny) - 1, int64_t(e.point / nx / ny) - 1};
  }

  static constexpr double kMinT = 1.0 / 1024;
  std::vector<std::array<EdgeId, 3>> triangles;

 private:
  static double squaredLength(const Vec3& v) { return v.x * v.x + v.y * v.y + v.z * v.z; }
  std::array<uint32_t, 3> n_;
};

// The cubes of one layer k of the padded lattice (lowest corners (i, j, k), i from -1 to n_x - 1 and j from -1 to
// n_y - 1) whose corners are not all on one side, row by row: the cubes between the rows (j, k), (j + 1, k),
// (j, k + 1), (j + 1, k + 1). Cubes touching a band cell or the grid's x ends are looked at one by one; between them
// every row is one run of cells outside the band, with one side, so a stretch of cubes is skipped at once when the
// four sides agree. Layers are independent: each is marched by one thread into its own Marcher, in cube order.
void marchLayer(const Grid& grid, const Band& band, double level, int64_t k, Marcher& out, LevelSurfaceStats& stats) {
  const auto& n = grid.dims;
  const int64_t nx = n[0], ny = n[1], nz = n[2];
  std::vector<int64_t> candidates;
  std::vector<size_t> runEnd;  // candidates[runEnd[r - 1], runEnd[r]) ascend; the first run is {-1, nx - 1}
  for (int64_t j = -1; j < ny; ++j) {
    // Rows (j, k), (j + 1, k), (j, k + 1), (j + 1, k + 1): cube corner v lies on row (v >> 1) & 3.
    std::array<Band::RowCursor, 4> rows{Band::RowCursor(band, j, k), Band::RowCursor(band, j + 1, k),
                                        Band::RowCursor(band, j, k + 1), Band::RowCursor(band, j + 1, k + 1)};
    const auto visit = [&](int64_t i) {
      std::array<Corner, 8> c;
      for (int v = 0; v < 8; ++v) c[size_t(v)] = rows[size_t((v >> 1) & 3)].at(i + (v & 1));
      int inside = 0;
      for (const Corner& x : c) inside += x.inside;
      if (inside == 0 || inside == 8) return;
      ++stats.cubes;
      const size_t before = out.triangles.size();
      out.march({i, j, k}, c, grid, level);
      for (const Corner& x : c)
        if (x.kind == Kind::BeyondGrid) {
          stats.capTriangles += out.triangles.size() - before;
          break;
        }
    };
    candidates.assign({-1, nx - 1});
    runEnd.assign({2});
    for (int64_t dk = 0; dk < 2; ++dk)
      for (int64_t dj = 0; dj < 2; ++dj) {
        if (j + dj < 0 || j + dj >= ny || k + dk < 0 || k + dk >= nz) continue;
        const uint64_t row = uint64_t(j + dj) + uint64_t(ny) * uint64_t(k + dk);
        for (uint64_t b = band.rowBegin(row); b < band.rowEnd(row); ++b) {
          const int64_t i = int64_t(grid.sdfKeys[b] % uint64_t(nx));
          candidates.push_back(i - 1);
          if (i < nx - 1) candidates.push_back(i);
        }
        runEnd.push_back(candidates.size());
      }
    // Each row's candidates ascend (its band cells do): merge the four runs instead of sorting.
    for (size_t r = 1; r < runEnd.size(); ++r)
      std::inplace_merge(candidates.begin(), candidates.begin() + ptrdiff_t(runEnd[r - 1]),
                         candidates.begin() + ptrdiff_t(runEnd[r]));
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    int64_t next = -1;  // the first cube not yet looked at
    for (const int64_t c : candidates) {
      if (c > next) {  // cubes next .. c - 1: every row one run outside the band
        bool side[4];
        for (int r = 0; r < 4; ++r) side[r] = rows[size_t(r)].at(next).inside;
        if (!(side[0] == side[1] && side[1] == side[2] && side[2] == side[3]))
          for (int64_t i = next; i < c; ++i) visit(i);
      }
      visit(c);
      next = c + 1;
    }
  }
}

}  // namespace level_surface_impl

namespace level_surface_impl {

// A number in a message, shortest round trip: a range must not be rounded into a contradiction with the value.
std::string exact(double x) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, x).ptr);
}

// The smallest cell edge h and the cell diagonal D.
std::array<double, 2> cellScales(const Grid& grid) {
  double smallest = INFINITY, diagonal = 0;
  for (int a = 0; a < 3; ++a) {
    const double pitch = (grid.bounds.hi[a] - grid.bounds.lo[a]) / double(grid.dims[a]);
    smallest = std::min(smallest, pitch);
    diagonal += pitch * pitch;
  }
  return {smallest, std::sqrt(diagonal)};
}

double largestLevel(const Grid& grid, double halfWidth) {
  const auto [h, d] = cellScales(grid);
  return halfWidth * h - d;
}

}  // namespace level_surface_impl

double largestSurfaceLevel(const Grid& grid) {
  if (grid.sdfHalfWidth == 0) return 0;
  return level_surface_impl::largestLevel(grid, grid.sdfHalfWidth);
}

double surfaceHalfWidth(const Grid& grid, double level) {
  using namespace level_surface_impl;
  if (!std::isfinite(level)) fail<InputError>("surface level ", level, " is not a finite number");
  const auto [h, d] = cellScales(grid);
  double half = std::max(3.0, (std::abs(level) + d) / h);
  for (int n = 0; n < 64 && largestLevel(grid, half) < std::abs(level); ++n) half = std::nextafter(half, INFINITY);
  if (half > 64 || largestLevel(grid, half) < std::abs(level))
    fail<InputError>("surface level ", exact(level), " is outside [", exact(-largestLevel(grid, 64)), ", ",
                     exact(largestLevel(grid, 64)),
                     "], the levels a band of 64 cell widths (the widest) holds with a cell's diagonal to spare "
                     "at these cells");
  return half;
}

VoxelMesh extractLevelSurface(const Grid& grid, double level, LevelSurfaceStats* statsOut,
                              const std::function<bool(double)>& progress) {
  using namespace level_surface_impl;
  const auto start = std::chrono::steady_clock::now();
  if (grid.sdfHalfWidth == 0) fail<InputError>("the grid has no signed distances: voxelize it with --sdf");
  VOX_CHECK(grid.sdfKeys.size() == grid.sdfValues.size());
  if (!std::isfinite(level)) fail<InputError>("surface level ", exact(level), " is not a finite number");
  const double largest = largestSurfaceLevel(grid);
  if (!(std::abs(level) <= largest)) {
    // The half-width to suggest, rounded up to thousandths and checked, so that following the advice works.
    const auto [h, d] = cellScales(grid);
    double needed = std::ceil((std::abs(level) + d) / h * 1000) / 1000;
    while (largestLevel(grid, needed) < std::abs(level) && needed <= 64) needed += 0.001;
    const std::string advice = needed <= 64 ? "voxelize with --sdf " + exact(needed) + " or more"
                                            : "no band (at most --sdf 64) holds it at these cells";
    if (largest < 0)
      fail<InputError>("surface: the distance band (--sdf ", exact(grid.sdfHalfWidth),
                       ") is narrower than a cell's diagonal; ", advice);
    fail<InputError>("surface level ", exact(level), " is outside [", exact(-largest), ", ", exact(largest),
                     "], the levels the distance band (--sdf ", exact(grid.sdfHalfWidth),
                     ") holds with a cell's diagonal to spare; ", advice);
  }

  LevelSurfaceStats stats;
  const Band band(grid, level);
  voxel_surface::ExportProgress report(progress, "surface");
  report.phase(0, 0.8);
  // Layers of cubes (padded z from 0 to n_z), each marched on its own into its own list: concatenated in layer order
  // they are the cubes in the serial order, so the output does not depend on threads.
  const size_t layers = size_t(grid.dims[2]) + 1;
  std::vector<Marcher> marched(layers, Marcher(grid));
  std::vector<LevelSurfaceStats> layerStats(layers);
  report.parallelFor(layers, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t l = r.begin(); l != r.end(); ++l)
      marchLayer(grid, band, level, int64_t(l) - 1, marched[l], layerStats[l]);
  });
  std::vector<size_t> firstTriangle(layers + 1, 0);
  for (size_t l = 0; l < layers; ++l) {
    stats.cubes += layerStats[l].cubes;
    stats.capTriangles += layerStats[l].capTriangles;
    firstTriangle[l + 1] = firstTriangle[l] + marched[l].triangles.size();
  }
  const size_t triangleCount = firstTriangle[layers];

  if (triangleCount > std::numeric_limits<uint32_t>::max() / 3)
    fail<LimitError>("surface: ", triangleCount, " triangles, more than a mesh of 32-bit indices holds");

  // One vertex per lattice edge, in edge order. An edge's lower end lies in the padded z plane of its cube's layer
  // or the next one, and edge order is plane by plane (the plane is the major part of the point's index): each
  // plane's triangle corners, from the two layers touching it, sorted by edge on their own and laid one plane after
  // the other give the edges in order, and each corner its vertex, with no search.
  report.phase(0.8, 0.9);
  const uint64_t planeSize = (uint64_t(grid.dims[0]) + 2) * (uint64_t(grid.dims[1]) + 2);
  const size_t planes = layers + 1;
  struct CornerRef {
    uint64_t key;     // (point within the plane) * 8 + direction: the edge's order within its plane
    uint32_t corner;  // 3 * face + v
  };
  std::vector<std::vector<CornerRef>> planeCorners(planes);
  std::vector<size_t> planeVertices(planes, 0);
  report.parallelFor(planes, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t p = r.begin(); p != r.end(); ++p) {
      std::vector<CornerRef>& refs = planeCorners[p];
      for (size_t l = p == 0 ? 0 : p - 1; l <= std::min(p, layers - 1); ++l)
        for (size_t t = 0; t < marched[l].triangles.size(); ++t)
          for (size_t v = 0; v < 3; ++v) {
            const EdgeId& e = marched[l].triangles[t][v];
            if (e.point / planeSize == p)
              refs.push_back({(e.point % planeSize) << 3 | e.dir, uint32_t(3 * (firstTriangle[l] + t) + v)});
          }
      std::sort(refs.begin(), refs.end(), [](const CornerRef& a, const CornerRef& b) { return a.key < b.key; });
      size_t distinct = 0;
      for (size_t c = 0; c < refs.size(); ++c) distinct += c == 0 || refs[c].key != refs[c - 1].key;
      planeVertices[p] = distinct;
    }
  });
  std::vector<size_t> firstVertex(planes + 1, 0);
  for (size_t p = 0; p < planes; ++p) firstVertex[p + 1] = firstVertex[p] + planeVertices[p];
  const size_t vertexCount = firstVertex[planes];
  if (vertexCount > std::numeric_limits<uint32_t>::max())
    fail<LimitError>("surface: ", vertexCount, " vertices and ", triangleCount,
                     " triangles, more than a mesh of 32-bit indices holds");

  VoxelMesh mesh;
  report.phase(0.9, 1);
  mesh.positions.resize(vertexCount);
  mesh.faceStart.resize(triangleCount + 1);
  mesh.faceVertices.resize(triangleCount * 3);
  report.parallelFor(planes, [&](const tbb::blocked_range<size_t>& r) {
    const Marcher& m = marched[0];
    for (size_t p = r.begin(); p != r.end(); ++p) {
      size_t vertex = firstVertex[p];
      const std::vector<CornerRef>& refs = planeCorners[p];
      for (size_t c = 0; c < refs.size(); ++c) {
        if (c > 0 && refs[c].key == refs[c - 1].key) {
          mesh.faceVertices[refs[c].corner] = uint32_t(vertex - 1);
          continue;
        }
        const EdgeId edge{p * planeSize + (refs[c].key >> 3), refs[c].key & 7};
        const std::array<int64_t, 3> lo = m.lowerEnd(edge);
        const auto dir = uint8_t(edge.dir);
        // The edge seen from the cube whose lowest corner is its lower end: corners 0 and dir.
        std::array<Corner, 8> corners;
        corners[0] = band.at(lo[0], lo[1], lo[2]);
        corners[dir] = band.at(lo[0] + (dir & 1), lo[1] + ((dir >> 1) & 1), lo[2] + ((dir >> 2) & 1));
        mesh.positions[vertex] = m.position(lo, 0, dir, corners, grid, level);
        mesh.faceVertices[refs[c].corner] = uint32_t(vertex++);
      }
    }
  });
  for (size_t f = 0; f < triangleCount; ++f) mesh.faceStart[f + 1] = uint32_t(3 * (f + 1));
  report.check();
  if (progress && !progress(1)) throw Error("surface cancelled");
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (statsOut) *statsOut = stats;
  return mesh;
}

}  // namespace vox
