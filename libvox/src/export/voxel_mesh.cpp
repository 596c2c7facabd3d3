// Voxel meshes (voxel_mesh.h). Pure geometry: no file I/O here.
//
// The exposed surface is built brick by brick: voxels are bucketed into 8x8x8 bricks held in a hash map, and each
// brick copies the occupancy of its neighbourhood into a small dense array, so every neighbour test is an array
// read and memory grows with the voxels, never with the grid's dimensions.
//
// Vertex splitting. Around a lattice point p lie eight cells (octants) and twelve quarter squares (slots), each
// between two octants that differ along one axis; a slot carries a face when exactly one of its two octants is a
// voxel. Around each of the six unit edges leaving p, the faces come in 0, 2 or 4; two faces pair up (they will
// share that edge), and four faces (two diagonal voxels, two diagonal empty cells: a "checkerboard" edge) pair
// either around each voxel (voxels kept apart, the default) or around each empty cell (voxels joined). The pairs
// link the faces at p into cycles, and each cycle becomes one vertex: that makes every vertex a single fan.
// An edge still gets four faces on one vertex pair when the two diagonal voxels are joined by other voxels around
// both of its ends (keeping them apart collapses a thin tunnel onto the edge); exactly then the edge joins the
// voxels instead. A voxel path around an end that joins them cuts the empty cells apart around that end (the path
// and the edge close a loop on the small sphere around the end, separating the two empty cells), so the joined
// choice is always safe, and because joining at one edge only happens when face-adjacent voxels already connect
// the pair around both ends, the choice at one edge never changes the connectivity that decides another.
#include "vox/export/voxel_mesh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>
#include <unordered_map>

#include "vox/export/cell_color.h"
#include "vox/export/colormap.h"
#include "vox/core/error.h"
#include "vox/io/input_file.h"

namespace vox {

FaceMode parseFaceMode(const std::string& name) {
  for (auto m : {FaceMode::All, FaceMode::Exposed, FaceMode::Merged})
    if (faceModeName(m) == name) return m;
  fail<InputError>("unknown face mode '", name, "' (expected all, exposed or merged)");
}

ColorMode parseColorMode(const std::string& name) {
  for (auto m : {ColorMode::Count, ColorMode::Material, ColorMode::None})
    if (colorModeName(m) == name) return m;
  fail<InputError>("unknown colour mode '", name, "' (expected count, material or none)");
}

std::string faceModeName(FaceMode mode) {
  switch (mode) {
    case FaceMode::All:
      return "all";
    case FaceMode::Exposed:
      return "exposed";
    case FaceMode::Merged:
      return "merged";
  }
  return "unknown";
}

std::string colorModeName(ColorMode mode) {
  switch (mode) {
    case ColorMode::Count:
      return "count";
    case ColorMode::Material:
      return "material";
    case ColorMode::None:
      return "none";
  }
  return "unknown";
}

namespace {

constexpr uint32_t kNoColor = 0;
// Colours are packed as 0x01BBGGRR: the top byte marks "has a colour", so that every colour differs from kNoColor.
uint32_t packColor(const Rgb8& c) { return 0x01000000u | c[0] | (uint32_t(c[1]) << 8) | (uint32_t(c[2]) << 16); }
Rgb8 unpackColor(uint32_t c) { return {uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)}; }
uint8_t toByte(double x) { return uint8_t(std::lround(std::clamp(std::isfinite(x) ? x : 0.0, 0.0, 1.0) * 255.0)); }
Rgb8 toRgb8(const Vec3& c) { return {toByte(c.x), toByte(c.y), toByte(c.z)}; }

// ---------------------------------------------------------------------------------------------------------------
// Voxels and their colours.

struct Voxels {
  std::vector<uint64_t> keys;    // sorted, unique
  std::vector<uint32_t> colors;  // packed, kNoColor without colour
};

uint32_t majorityMaterialColor(const Grid& grid, const Scene& scene, size_t cell) {
  return packColor(toRgb8(cellMaterialColor(grid, scene, cell)));  // image textures included (cell_color.h)
}

// The packed colour of each occupied cell (kNoColor for ColorMode::None); shared by the meshes and by
// occupiedCellColors (the voxel formats), so a cell has one colour in every export. Count reads only cellStart,
// against maxCount (0: the grid's own largest count).
std::vector<uint32_t> occupiedColors(const Grid& grid, const Scene& scene, ColorMode mode, uint32_t maxCount = 0) {
  const size_t nOcc = grid.cellKeys.size();
  if (grid.cellStart.size() != nOcc + 1 || (mode != ColorMode::Count && grid.cellStart.back() > grid.primIds.size()))
    fail<InputError>("grid: inconsistent cell table (", nOcc, " cells, ", grid.cellStart.size(), " offsets)");
  std::vector<uint32_t> occColor(nOcc, kNoColor);
  if (mode == ColorMode::Count) {
    if (maxCount == 0) maxCount = largestCellCount(grid);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nOcc), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t c = r.begin(); c != r.end(); ++c)
        occColor[c] = packColor(toRgb8(countColor(uint32_t(grid.cellStart[c + 1] - grid.cellStart[c]), maxCount)));
    });
  } else if (mode == ColorMode::Material) {
    std::mutex errorMutex;
    std::exception_ptr error;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nOcc), [&](const tbb::blocked_range<size_t>& r) {
      try {
        for (size_t c = r.begin(); c != r.end(); ++c) occColor[c] = majorityMaterialColor(grid, scene, c);
      } catch (...) {
        std::lock_guard lock(errorMutex);
        if (!error) error = std::current_exception();
      }
    });
    if (error) std::rethrow_exception(error);
  }
  return occColor;
}

Voxels gatherVoxels(const Grid& grid, const Scene& scene, ColorMode mode) {
  const uint64_t cellCount = grid.cellCount();
  const size_t nOcc = grid.cellKeys.size();
  if (grid.cellStart.size() != nOcc + 1 || grid.cellStart.back() > grid.primIds.size())
    fail<InputError>("grid: inconsistent cell table (", nOcc, " cells, ", grid.cellStart.size(), " offsets)");
  auto checkSorted = [&](const std::vector<uint64_t>& keys, const char* what) {
    for (size_t i = 0; i < keys.size(); ++i) {
      if (keys[i] >= cellCount) fail<InputError>("grid: ", what, " key ", keys[i], " outside the grid");
      if (i > 0 && keys[i] <= keys[i - 1]) fail<InputError>("grid: ", what, " keys not sorted at index ", i);
    }
  };
  checkSorted(grid.cellKeys, "cell");
  checkSolidRuns(grid.solidRuns, cellCount, "grid");
  const uint64_t solidCount = grid.solidCount();
  checkMemory((nOcc + solidCount) * 12, "grid", "the voxel list");

  const std::vector<uint32_t> occColor = occupiedColors(grid, scene, mode);

  // Merge occupied keys and solid runs; a cell in both is drawn once, with its occupied colour.
  const uint32_t solid = mode == ColorMode::None ? kNoColor : packColor(kSolidCellColor);
  Voxels v;
  v.keys.reserve(nOcc + solidCount);
  v.colors.reserve(nOcc + solidCount);
  size_t a = 0;
  for (const CellRun& run : grid.solidRuns) {
    for (uint64_t key = run.first; key < run.first + run.count; ++key) {
      for (; a < nOcc && grid.cellKeys[a] < key; ++a) {
        v.keys.push_back(grid.cellKeys[a]);
        v.colors.push_back(occColor[a]);
      }
      if (a < nOcc && grid.cellKeys[a] == key) continue;  // occupied wins; pushed by the loop above next time
      v.keys.push_back(key);
      v.colors.push_back(solid);
    }
  }
  for (; a < nOcc; ++a) {
    v.keys.push_back(grid.cellKeys[a]);
    v.colors.push_back(occColor[a]);
  }
  return v;
}

// The lattice coordinate of cell boundary i on each axis, in world space.
struct Lattice {
  Box bounds;
  std::array<uint32_t, 3> dims;
  Vec3 point(uint64_t i, uint64_t j, uint64_t k) const {
    return {cellBoundary(bounds, dims, 0, int64_t(i)), cellBoundary(bounds, dims, 1, int64_t(j)),
            cellBoundary(bounds, dims, 2, int64_t(k))};
  }
};

void checkVertexCount(uint64_t n) {
  if (n >= (uint64_t(1) << 32))
    fail<LimitError>("voxel mesh: ", n, " vertices exceed the 2^32 limit of the mesh formats");
}

// ---------------------------------------------------------------------------------------------------------------
// FaceMode::All

VoxelMesh buildCubes(const Voxels& vox, const Lattice& lat, bool colored) {
  const size_t n = vox.keys.size();
  checkVertexCount(uint64_t(n) * 8);
  VoxelMesh mesh;
  mesh.positions.resize(n * 8);
  mesh.faceVertices.resize(n * 36);
  mesh.faceStart.resize(n * 12 + 1);
  if (colored) mesh.faceColors.resize(n * 12);
  // Corner c of the cube is (c&1, c>>1&1, c>>2&1); the triangles are counter-clockwise seen from outside.
  static constexpr uint8_t kTris[12][3] = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5},   // -x, +x
                                           {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},   // -y, +y
                                           {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};  // -z, +z
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const auto ijk = cellIndex(lat.dims, vox.keys[v]);
      for (uint32_t c = 0; c < 8; ++c)
        mesh.positions[v * 8 + c] = lat.point(ijk[0] + (c & 1), ijk[1] + ((c >> 1) & 1), ijk[2] + ((c >> 2) & 1));
      for (size_t t = 0; t < 12; ++t) {
        for (int k = 0; k < 3; ++k) mesh.faceVertices[v * 36 + t * 3 + k] = uint32_t(v * 8 + kTris[t][k]);
        mesh.faceStart[v * 12 + t + 1] = uint32_t(v * 36 + t * 3 + 3);
        if (colored) mesh.faceColors[v * 12 + t] = unpackColor(vox.colors[v]);
      }
    }
  });
  return mesh;
}

// ---------------------------------------------------------------------------------------------------------------
// Lattice-point tables. Octant o = dx | dy<<1 | dz<<2 is the cell p - (1,1,1) + (dx,dy,dz). Slot s = 4a + bb + 2bc
// is the quarter square through p perpendicular to axis a, on side bb of axis b = (a+1)%3 and side bc of axis
// c = (a+2)%3. Edge e = 2a + side is the unit edge from p along axis a, towards - (side 0) or + (side 1).
// A configuration is occ | dec << 8: occ the eight octant bits, dec one bit per checkerboard edge (1: join the
// voxels, i.e. pair the faces around the empty cells).

constexpr uint8_t kNoCycle = 0xFF;

int octantOf(int a, int bitA, int bitB, int bitC) {
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  return (bitA << a) | (bitB << b) | (bitC << c);
}
int slotOf(int n, int bitAxis1, int bitAxis2) { return 4 * n + bitAxis1 + 2 * bitAxis2; }  // bits of (n+1)%3, (n+2)%3

// The four slots around edge (a, side), with the octants on either side: faces F[0..3] are
// {b-face at bc=0, b-face at bc=1, c-face at bb=0, c-face at bb=1}.
struct EdgeSlots {
  int slot[4];
  int octA[4], octB[4];  // the two octants each slot separates
};

EdgeSlots edgeSlots(int a, int side) {
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  auto q = [&](int bb, int bc) { return octantOf(a, side, bb, bc); };
  // Bits of an octant along an axis, to express slots in the frame of their own normal.
  auto slotBetween = [&](int n, int o) {
    const int n1 = (n + 1) % 3, n2 = (n + 2) % 3;
    return slotOf(n, (o >> n1) & 1, (o >> n2) & 1);
  };
  EdgeSlots e{};
  for (int bc = 0; bc < 2; ++bc) {  // faces perpendicular to b, between q(0,bc) and q(1,bc)
    e.slot[bc] = slotBetween(b, q(0, bc));
    e.octA[bc] = q(0, bc);
    e.octB[bc] = q(1, bc);
  }
  for (int bb = 0; bb < 2; ++bb) {  // faces perpendicular to c, between q(bb,0) and q(bb,1)
    e.slot[2 + bb] = slotBetween(c, q(bb, 0));
    e.octA[2 + bb] = q(bb, 0);
    e.octB[2 + bb] = q(bb, 1);
  }
  return e;
}

struct PointTables {
  std::array<uint8_t, 256> checkerEdges{};     // bit e: edge e has four faces
  std::vector<std::array<uint8_t, 12>> cycle;  // [config][slot] -> cycle id or kNoCycle
  std::vector<uint8_t> cycleCount;             // [config]
  std::array<EdgeSlots, 6> edges;

  PointTables() : cycle(1 << 14), cycleCount(1 << 14, 0) {
    for (int e = 0; e < 6; ++e) edges[e] = edgeSlots(e / 2, e % 2);
    for (int occ = 0; occ < 256; ++occ) {
      auto filled = [&](int o) { return (occ >> o) & 1; };
      for (int e = 0; e < 6; ++e) {
        const EdgeSlots& es = edges[e];
        int faces = 0;
        for (int f = 0; f < 4; ++f) faces += filled(es.octA[f]) != filled(es.octB[f]);
        if (faces == 4) checkerEdges[occ] |= uint8_t(1 << e);
      }
      for (int dec = 0; dec < 64; ++dec) {
        if ((dec & ~checkerEdges[occ]) != 0) continue;  // only canonical configurations are looked up
        const int config = occ | (dec << 8);
        std::array<int, 12> parent;
        std::iota(parent.begin(), parent.end(), 0);
        auto find = [&](int x) {
          while (parent[x] != x) x = parent[x] = parent[parent[x]];
          return x;
        };
        auto unite = [&](int x, int y) { parent[find(x)] = find(y); };
        std::array<bool, 12> has{};
        for (int s = 0; s < 12; ++s) {
          const int n = s / 4, n1 = (n + 1) % 3, n2 = (n + 2) % 3;
          const int o0 = (((s & 1)) << n1) | (((s >> 1) & 1) << n2);
          has[s] = filled(o0) != filled(o0 | (1 << n));
        }
        for (int e = 0; e < 6; ++e) {
          const EdgeSlots& es = edges[e];
          int present[4], np = 0;
          for (int f = 0; f < 4; ++f)
            if (has[es.slot[f]]) present[np++] = f;
          if (np == 2) {
            unite(es.slot[present[0]], es.slot[present[1]]);
          } else if (np == 4) {
            // Octant q(0,0) is octA of faces 0 and 2. Pair the two faces around q(0,0) (and the two around q(1,1))
            // when q(0,0) is the kind of cell to keep apart: a voxel by default, an empty cell when joining.
            const bool q00Filled = filled(es.octA[0]);
            const bool join = (dec >> e) & 1;
            if (q00Filled != join) {
              unite(es.slot[0], es.slot[2]);
              unite(es.slot[1], es.slot[3]);
            } else {
              unite(es.slot[0], es.slot[3]);
              unite(es.slot[1], es.slot[2]);
            }
          }
        }
        std::array<int, 12> rootId;
        rootId.fill(-1);
        int count = 0;
        for (int s = 0; s < 12; ++s) {
          cycle[config][s] = kNoCycle;
          if (!has[s]) continue;
          const int r = find(s);
          if (rootId[r] < 0) rootId[r] = count++;
          cycle[config][s] = uint8_t(rootId[r]);
        }
        cycleCount[config] = uint8_t(count);
      }
    }
  }
};

const PointTables& pointTables() {
  static const PointTables tables;
  return tables;
}

// ---------------------------------------------------------------------------------------------------------------
// Bricks.

constexpr int kBrickBits = 3;
constexpr int kBrick = 1 << kBrickBits;         // 8 cells per brick edge
constexpr int kPadLo = 2, kPadHi = 2;           // cells copied around a brick: vertex decisions look two cells down
constexpr int kPad = kBrick + kPadLo + kPadHi;  // 12
constexpr int kKeyBits = 21;
constexpr uint64_t kKeyMask = (uint64_t(1) << kKeyBits) - 1;

uint64_t brickKey(uint64_t bx, uint64_t by, uint64_t bz) { return bx | (by << kKeyBits) | (bz << (2 * kKeyBits)); }
std::array<int64_t, 3> brickCoords(uint64_t key) {
  return {int64_t(key & kKeyMask), int64_t((key >> kKeyBits) & kKeyMask), int64_t(key >> (2 * kKeyBits))};
}

struct Brick {
  uint64_t key = 0;
  std::array<uint64_t, kBrick> mask{};  // mask[z] bit x + 8y
  uint32_t firstVoxel = 0;              // colours of the brick's voxels, in local index order, start here
};

struct BrickSet {
  std::vector<Brick> bricks;  // sorted by key
  std::vector<uint32_t> colors;
  std::unordered_map<uint64_t, uint32_t> index;

  const Brick* find(int64_t bx, int64_t by, int64_t bz) const {
    if (bx < 0 || by < 0 || bz < 0) return nullptr;
    auto it = index.find(brickKey(uint64_t(bx), uint64_t(by), uint64_t(bz)));
    return it == index.end() ? nullptr : &bricks[it->second];
  }
};

BrickSet buildBricks(const Voxels& vox, const std::array<uint32_t, 3>& dims) {
  struct Entry {
    uint64_t brick;
    uint32_t local;
    uint32_t color;
  };
  std::vector<Entry> entries(vox.keys.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, entries.size()), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const auto ijk = cellIndex(dims, vox.keys[v]);
      entries[v] = {brickKey(ijk[0] >> kBrickBits, ijk[1] >> kBrickBits, ijk[2] >> kBrickBits),
                    uint32_t((ijk[0] & 7) | ((ijk[1] & 7) << 3) | ((ijk[2] & 7) << 6)), vox.colors[v]};
    }
  });
  tbb::parallel_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.brick != b.brick ? a.brick < b.brick : a.local < b.local;
  });
  BrickSet set;
  set.colors.resize(entries.size());
  for (size_t v = 0; v < entries.size(); ++v) {
    if (set.bricks.empty() || set.bricks.back().key != entries[v].brick) {
      set.bricks.push_back({});
      set.bricks.back().key = entries[v].brick;
      set.bricks.back().firstVoxel = uint32_t(v);
    }
    const uint32_t l = entries[v].local;
    set.bricks.back().mask[l >> 6] |= uint64_t(1) << (l & 63);
    set.colors[v] = entries[v].color;
  }
  set.index.reserve(set.bricks.size() * 2);
  for (uint32_t b = 0; b < set.bricks.size(); ++b) set.index.emplace(set.bricks[b].key, b);
  return set;
}

// Occupancy of the cells around one brick: local cell coordinates -kPadLo .. kBrick + kPadHi - 1.
struct Pad {
  // rows[z][y] bit (x + kPadLo): cell (x, y, z) in local cell coordinates, each from -kPadLo to kBrick + kPadHi - 1.
  std::array<std::array<uint16_t, kPad>, kPad> rows;

  bool at(int x, int y, int z) const { return (rows[z + kPadLo][y + kPadLo] >> (x + kPadLo)) & 1; }
  uint32_t row(int y, int z) const { return rows[z + kPadLo][y + kPadLo]; }

  void fill(const BrickSet& set, int64_t bx, int64_t by, int64_t bz) {
    for (auto& r : rows) r.fill(0);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Brick* b = set.find(bx + dx, by + dy, bz + dz);
          if (!b) continue;
          // The part of neighbour (dx,dy,dz) that falls inside the padded range, in its own local coordinates.
          auto range = [](int d) -> std::array<int, 2> {
            if (d < 0) return {kBrick - kPadLo, kBrick};
            if (d > 0) return {0, kPadHi};
            return {0, kBrick};
          };
          const auto ry = range(dy), rz = range(dz);
          for (int z = rz[0]; z < rz[1]; ++z) {
            const uint64_t layer = b->mask[z];
            if (!layer) continue;
            for (int y = ry[0]; y < ry[1]; ++y) {
              const uint32_t bits = uint32_t((layer >> (8 * y)) & 0xFF);
              if (!bits) continue;
              // Bit x of the neighbour's row is local x + dx*kBrick, stored at bit x + dx*kBrick + kPadLo.
              const int shift = dx * kBrick + kPadLo;
              const uint32_t placed = shift >= 0 ? bits << shift : bits >> -shift;
              rows[z + dz * kBrick + kPadLo][y + dy * kBrick + kPadLo] |= uint16_t(placed & ((1u << kPad) - 1));
            }
          }
        }
  }

  // The eight octant bits around lattice point (x,y,z): octant dx | dy<<1 | dz<<2 is cell (x-1+dx, y-1+dy, z-1+dz).
  int octants(int x, int y, int z) const {
    const int s = x - 1 + kPadLo;
    return int((row(y - 1, z - 1) >> s) & 3) | int(((row(y, z - 1) >> s) & 3) << 2) |
           int(((row(y - 1, z) >> s) & 3) << 4) | int(((row(y, z) >> s) & 3) << 6);
  }

  // Decision for checkerboard edge e at lattice point (x,y,z) (local lattice coordinates, 0..kBrick): join the two
  // diagonal voxels when face-adjacent voxels connect them around both ends of the edge.
  bool joinEdge(int x, int y, int z, int e) const {
    const int a = e / 2, side = e % 2, b = (a + 1) % 3, c = (a + 2) % 3;
    int p[3] = {x, y, z};
    const int m = side ? p[a] : p[a] - 1;  // axis-a index of the four cells around the edge
    auto cell = [&](int layer, int bb, int bc) {
      int q[3];
      q[a] = layer;
      q[b] = p[b] - 1 + bb;
      q[c] = p[c] - 1 + bc;
      return at(q[0], q[1], q[2]);
    };
    // The voxels' diagonal: (0,0)-(1,1) or (1,0)-(0,1).
    const bool diag00 = cell(m, 0, 0);
    auto connected = [&](int layer) {
      if (diag00) return cell(layer, 0, 0) && cell(layer, 1, 1) && (cell(layer, 1, 0) || cell(layer, 0, 1));
      return cell(layer, 1, 0) && cell(layer, 0, 1) && (cell(layer, 0, 0) || cell(layer, 1, 1));
    };
    return connected(m - 1) && connected(m + 1);
  }

  // Configuration of lattice point (x,y,z), local lattice coordinates in [0, kBrick].
  uint16_t config(int x, int y, int z, const PointTables& t) const {
    const int occ = octants(x, y, z);
    int dec = 0;
    for (uint8_t ce = t.checkerEdges[occ]; ce; ce &= uint8_t(ce - 1)) {
      const int e = std::countr_zero(ce);
      if (joinEdge(x, y, z, e)) dec |= 1 << e;
    }
    return uint16_t(occ | (dec << 8));
  }
};

// One exposed unit square: the plane x_axis = plane, facing + (positive) or -, with its minimum corner at in-plane
// coordinates (u, v) along axes (axis+1)%3 and (axis+2)%3, and its vertices at corners (0,0) (1,0) (1,1) (0,1).
struct Square {
  std::array<uint32_t, 4> vid;
  uint32_t color;
  uint32_t u, v, plane;
  uint8_t axis, positive;
};

struct ExposedSurface {
  std::vector<Vec3> positions;
  std::vector<uint8_t> split;  // per vertex: its lattice point has several vertices (several sheets of surface)
  std::vector<Square> squares;
};

// The bricks owning lattice points of the voxels' corners, sorted by key: lattice point (i,j,k) belongs to brick
// (i,j,k) >> 3, and the corners of a voxel reach one brick up on each axis.
struct WorkBricks {
  std::vector<uint64_t> keys;
  std::unordered_map<uint64_t, uint32_t> index;  // key -> position in keys
};

WorkBricks workBricks(const BrickSet& set) {
  WorkBricks work;
  work.keys.reserve(set.bricks.size() * 8);
  for (const Brick& b : set.bricks) {
    const auto c = brickCoords(b.key);
    for (int d = 0; d < 8; ++d)
      work.keys.push_back(
          brickKey(uint64_t(c[0] + (d & 1)), uint64_t(c[1] + ((d >> 1) & 1)), uint64_t(c[2] + (d >> 2))));
  }
  tbb::parallel_sort(work.keys.begin(), work.keys.end());
  work.keys.erase(std::unique(work.keys.begin(), work.keys.end()), work.keys.end());
  work.index.reserve(work.keys.size() * 2);
  for (uint32_t w = 0; w < work.keys.size(); ++w) work.index.emplace(work.keys[w], w);
  return work;
}

// The vertices' numbers: one vertex per cycle of a lattice point, numbered brick by brick. The vertices of local
// point l of work brick w are base[w] + firstLocal[w][l] up to the next point's first.
struct VertexNumbering {
  std::vector<std::array<uint16_t, 512>> firstLocal;
  std::vector<uint64_t> base;  // one more than the work bricks: base.back() is the vertex count
  uint32_t count(size_t w, int l) const {
    const uint32_t end = l + 1 < 512 ? firstLocal[w][l + 1] : uint32_t(base[w + 1] - base[w]);
    return end - firstLocal[w][l];
  }
};

VertexNumbering numberVertices(const BrickSet& set, const WorkBricks& work, const PointTables& tables) {
  const size_t nWork = work.keys.size();
  VertexNumbering num;
  num.firstLocal.resize(nWork);
  num.base.assign(nWork + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nWork), [&](const tbb::blocked_range<size_t>& r) {
    Pad pad;
    for (size_t w = r.begin(); w != r.end(); ++w) {
      const auto bc = brickCoords(work.keys[w]);
      pad.fill(set, bc[0], bc[1], bc[2]);
      uint32_t running = 0;
      for (int z = 0; z < kBrick; ++z)
        for (int y = 0; y < kBrick; ++y) {
          // A row of lattice points without any voxel around it has no vertex.
          const bool empty = (pad.row(y - 1, z - 1) | pad.row(y, z - 1) | pad.row(y - 1, z) | pad.row(y, z)) == 0;
          for (int x = 0; x < kBrick; ++x) {
            num.firstLocal[w][x + 8 * y + 64 * z] = uint16_t(running);
            if (!empty) {
              const int occ = pad.octants(x, y, z);
              if (occ != 0 && occ != 255) running += tables.cycleCount[pad.config(x, y, z, tables)];
            }
          }
        }
      num.base[w + 1] = running;
    }
  });
  for (size_t w = 0; w < nWork; ++w) num.base[w + 1] += num.base[w];
  checkVertexCount(num.base[nWork]);
  return num;
}

// The vertex ids at the corners of one brick's voxels, local lattice coordinates 0..kBrick: the corners at kBrick
// belong to the upper neighbours (`owner`, work-brick indices by d = dx | dy << 1 | dz << 2). Configurations are
// computed once per point.
class BrickVertexIds {
 public:
  BrickVertexIds(const Pad& pad, const PointTables& tables, const VertexNumbering& num,
                 const std::array<uint32_t, 8>& owner)
      : pad_(pad), tables_(tables), num_(num), owner_(owner) {
    configCache_.fill(-1);
  }
  uint32_t operator()(const int q[3], int slot) {
    const int ci = q[0] + (kBrick + 1) * (q[1] + (kBrick + 1) * q[2]);
    if (configCache_[ci] < 0) configCache_[ci] = pad_.config(q[0], q[1], q[2], tables_);
    const uint8_t cyc = tables_.cycle[configCache_[ci]][slot];
    VOX_CHECK(cyc != kNoCycle);
    const int d = (q[0] >> kBrickBits) | ((q[1] >> kBrickBits) << 1) | ((q[2] >> kBrickBits) << 2);
    const int l = (q[0] & 7) | ((q[1] & 7) << 3) | ((q[2] & 7) << 6);
    return uint32_t(num_.base[owner_[d]] + num_.firstLocal[owner_[d]][l] + cyc);
  }

 private:
  const Pad& pad_;
  const PointTables& tables_;
  const VertexNumbering& num_;
  const std::array<uint32_t, 8>& owner_;
  std::array<int32_t, (kBrick + 1) * (kBrick + 1) * (kBrick + 1)> configCache_;
};

// The exposed squares of one brick's voxels (origin: its first cell), with their vertex ids, appended to `squares`.
void brickSquares(const Brick& brick, const BrickSet& set, const Pad& pad, const std::array<int64_t, 3>& origin,
                  BrickVertexIds& vertexId, std::vector<Square>& squares) {
  uint32_t rank = 0;
  for (int z = 0; z < kBrick; ++z)
    for (uint64_t bits = brick.mask[z]; bits; bits &= bits - 1, ++rank) {
      const int bit = std::countr_zero(bits);
      const int cellLocal[3] = {bit & 7, bit >> 3, z};
      const uint32_t color = set.colors[brick.firstVoxel + rank];
      for (int a = 0; a < 3; ++a)
        for (int positive = 0; positive < 2; ++positive) {
          int n[3] = {cellLocal[0], cellLocal[1], cellLocal[2]};
          n[a] += positive ? 1 : -1;
          if (pad.at(n[0], n[1], n[2])) continue;
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          Square s;
          s.color = color;
          s.axis = uint8_t(a);
          s.positive = uint8_t(positive);
          s.plane = uint32_t(origin[a] + cellLocal[a] + positive);
          s.u = uint32_t(origin[b] + cellLocal[b]);
          s.v = uint32_t(origin[c] + cellLocal[c]);
          static constexpr int kCorner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          for (int k = 0; k < 4; ++k) {
            const int du = kCorner[k][0], dv = kCorner[k][1];
            int q[3];
            q[a] = cellLocal[a] + positive;
            q[b] = cellLocal[b] + du;
            q[c] = cellLocal[c] + dv;
            // Seen from corner q the square lies towards -b when du = 1, towards +b when du = 0.
            s.vid[k] = vertexId(q, slotOf(a, 1 - du, 1 - dv));
          }
          squares.push_back(s);
        }
    }
}

// The positions of work brick w's vertices (every vertex of a lattice point at the point), and whether a point has
// several.
void placeVertices(size_t w, const VertexNumbering& num, const Lattice& lat, const std::array<int64_t, 3>& origin,
                   ExposedSurface& out) {
  for (int l = 0; l < 512; ++l) {
    const uint32_t count = num.count(w, l);
    if (count == 0) continue;
    const Vec3 p =
        lat.point(uint64_t(origin[0] + (l & 7)), uint64_t(origin[1] + ((l >> 3) & 7)), uint64_t(origin[2] + (l >> 6)));
    const uint64_t first = num.base[w] + num.firstLocal[w][l];
    for (uint32_t c = 0; c < count; ++c) {
      out.positions[first + c] = p;
      out.split[first + c] = count > 1;
    }
  }
}

// The lists of squares one after another, in order, each freed once copied.
std::vector<Square> concatenate(std::vector<std::vector<Square>>& lists) {
  std::vector<size_t> offset(lists.size() + 1, 0);
  for (size_t w = 0; w < lists.size(); ++w) offset[w + 1] = offset[w] + lists[w].size();
  std::vector<Square> all(offset.back());
  tbb::parallel_for(size_t(0), lists.size(), [&](size_t w) {
    std::copy(lists[w].begin(), lists[w].end(), all.begin() + ptrdiff_t(offset[w]));
    std::vector<Square>().swap(lists[w]);
  });
  return all;
}

ExposedSurface buildExposed(const Voxels& vox, const Lattice& lat) {
  const PointTables& tables = pointTables();
  for (int a = 0; a < 3; ++a)
    if (lat.dims[a] >= (uint32_t(1) << (kKeyBits + kBrickBits)) - 2 * kBrick)
      fail<LimitError>("voxel mesh: grid dimension ", lat.dims[a], " too large for export");
  const BrickSet set = buildBricks(vox, lat.dims);
  const WorkBricks work = workBricks(set);
  const size_t nWork = work.keys.size();
  const VertexNumbering num = numberVertices(set, work, tables);

  ExposedSurface out;
  out.positions.resize(num.base[nWork]);
  out.split.resize(num.base[nWork]);
  std::vector<std::vector<Square>> perBrick(nWork);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nWork), [&](const tbb::blocked_range<size_t>& r) {
    Pad pad;
    for (size_t w = r.begin(); w != r.end(); ++w) {
      const auto bc = brickCoords(work.keys[w]);
      pad.fill(set, bc[0], bc[1], bc[2]);
      const std::array<int64_t, 3> origin = {bc[0] * kBrick, bc[1] * kBrick, bc[2] * kBrick};
      placeVertices(w, num, lat, origin, out);
      const auto occIt = set.index.find(work.keys[w]);
      if (occIt == set.index.end()) continue;
      std::array<uint32_t, 8> owner;
      for (int d = 0; d < 8; ++d)  // present by construction of the work bricks
        owner[d] = work.index.at(
            brickKey(uint64_t(bc[0] + (d & 1)), uint64_t(bc[1] + ((d >> 1) & 1)), uint64_t(bc[2] + (d >> 2))));
      BrickVertexIds vertexId(pad, tables, num, owner);
      brickSquares(set.bricks[occIt->second], set, pad, origin, vertexId, perBrick[w]);
    }
  });
  out.squares = concatenate(perBrick);
  return out;
}

VoxelMesh exposedMesh(ExposedSurface&& surface, bool colored) {
  VoxelMesh mesh;
  mesh.positions = std::move(surface.positions);
  const size_t n = surface.squares.size();
  mesh.faceStart.resize(n + 1);
  mesh.faceVertices.resize(4 * n);
  if (colored) mesh.faceColors.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const Square& s = surface.squares[f];
      // (u, v) axes are (axis+1, axis+2): counter-clockwise about +axis, reversed for faces looking down the axis.
      static constexpr int kOrder[2][4] = {{0, 3, 2, 1}, {0, 1, 2, 3}};
      for (int k = 0; k < 4; ++k) mesh.faceVertices[4 * f + k] = s.vid[kOrder[s.positive][k]];
      mesh.faceStart[f + 1] = uint32_t(4 * (f + 1));
      if (colored) mesh.faceColors[f] = unpackColor(s.color);
    }
  });
  return mesh;
}

// ---------------------------------------------------------------------------------------------------------------
// Rectangles with extra vertices on their sides as triangles.

// Triangles of one rectangle whose sides carry extra vertices, without zero-area triangles: a fan from the second
// vertex of the bottom side over the left side, a fan from the second vertex of the top side over the right side,
// and a zipper between what is left of the bottom and top sides (two parallel lines: every triangle has two
// vertices on one and one on the other).
void triangulateRectangle(const std::vector<uint32_t>& poly, const std::vector<Vec3>& pos,
                          const std::array<size_t, 4>& corner, std::vector<uint32_t>& tris) {
  const size_t n = poly.size();
  auto chain = [&](int side) {
    std::vector<uint32_t> c;
    for (size_t k = corner[side];; k = (k + 1) % n) {
      c.push_back(poly[k]);
      if (k == corner[(side + 1) % 4]) break;
    }
    return c;
  };
  const auto s0 = chain(0), s1 = chain(1), s2 = chain(2), s3 = chain(3);
  auto tri = [&](uint32_t a, uint32_t b, uint32_t c) { tris.insert(tris.end(), {a, b, c}); };
  const uint32_t apex0 = s0[1], apex2 = s2[1];
  for (size_t j = 0; j + 1 < s3.size(); ++j) tri(s3[j], s3[j + 1], apex0);
  for (size_t j = 0; j + 1 < s1.size(); ++j) tri(s1[j], s1[j + 1], apex2);
  const std::vector<uint32_t> bottom(s0.begin() + 1, s0.end());
  std::vector<uint32_t> top(s2.begin() + 1, s2.end());
  std::reverse(top.begin(), top.end());  // now runs the same way as bottom
  const Vec3 dir = pos[s0.back()] - pos[s0.front()];
  size_t i = 0, j = 0;
  while (i + 1 < bottom.size() || j + 1 < top.size()) {
    const bool advanceBottom =
        j + 1 >= top.size() || (i + 1 < bottom.size() && dot(pos[bottom[i + 1]], dir) <= dot(pos[top[j + 1]], dir));
    if (advanceBottom) {
      tri(bottom[i], bottom[i + 1], top[j]);
      ++i;
    } else {
      tri(bottom[i], top[j + 1], top[j]);
      ++j;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// FaceMode::Merged: greedy meshing of each plane's squares into rectangles of one colour.

// The squares bucketed by plane (axis, orientation, position) with a counting sort (the number of planes grows with
// the grid's side, not its volume): plane p's squares are order[planeStart[p], planeStart[p + 1]), keyed for sorting
// by (v, u), so that the greedy scan and its row lookups touch the squares themselves only to read vertices.
struct PlaneEntry {
  uint64_t key;  // v << 32 | u
  uint32_t color;
  uint32_t idx;  // in the squares
};
struct PlaneBuckets {
  std::vector<PlaneEntry> order;
  std::vector<uint32_t> planeStart;
  std::vector<size_t> planes;  // the planes holding squares
};

PlaneBuckets bucketByPlane(const std::vector<Square>& sq, const std::array<uint32_t, 3>& dims) {
  std::array<size_t, 4> axisBase{};
  for (int a = 0; a < 3; ++a) axisBase[a + 1] = axisBase[a] + 2 * (size_t(dims[a]) + 1);
  const size_t nPlanes = axisBase[3];
  auto planeOf = [&](const Square& s) { return axisBase[s.axis] + 2 * size_t(s.plane) + s.positive; };
  PlaneBuckets out;
  out.planeStart.assign(nPlanes + 1, 0);
  for (const Square& s : sq) ++out.planeStart[planeOf(s) + 1];
  for (size_t p = 0; p < nPlanes; ++p) out.planeStart[p + 1] += out.planeStart[p];
  out.order.resize(sq.size());
  std::vector<uint32_t> cursor(out.planeStart.begin(), out.planeStart.end() - 1);
  for (uint32_t i = 0; i < sq.size(); ++i)
    out.order[cursor[planeOf(sq[i])]++] = {(uint64_t(sq[i].v) << 32) | sq[i].u, sq[i].color, i};
  for (size_t p = 0; p < nPlanes; ++p)
    if (out.planeStart[p + 1] > out.planeStart[p]) out.planes.push_back(p);
  return out;
}

// The polygons of one plane: each lists its boundary vertices and marks which are its four corners.
struct PlanePolygons {
  std::vector<uint32_t> start{0};
  std::vector<uint32_t> verts;
  std::vector<uint8_t> corner;
  std::vector<uint32_t> colors;
};

// Appends the boundary of the w x h rectangle whose rows start at squares e[rowStart[r]], counter-clockwise about
// +axis in (u, v) (along v = 0, u = w, v = h, u = 0), reversed for a plane facing down its axis.
void addRectangle(const PlaneEntry* e, const std::vector<size_t>& rowStart, uint32_t w, const std::vector<Square>& sq,
                  uint32_t color, bool positive, PlanePolygons& po) {
  const uint32_t h = uint32_t(rowStart.size());
  auto vertexAt = [&](uint32_t du, uint32_t dv) {
    const uint32_t cu = std::min(du, w - 1), cv = std::min(dv, h - 1);
    const Square& s = sq[e[rowStart[cv] + cu].idx];
    const int k = (du - cu) + 2 * (dv - cv);  // corner (du-cu, dv-cv): 0 -> 00, 1 -> 10, 3 -> 11, 2 -> 01
    static constexpr int kCornerIndex[4] = {0, 1, 3, 2};
    return s.vid[kCornerIndex[k]];
  };
  const size_t begin = po.verts.size();
  for (uint32_t u = 0; u < w; ++u) po.verts.push_back(vertexAt(u, 0)), po.corner.push_back(u == 0);
  for (uint32_t v = 0; v < h; ++v) po.verts.push_back(vertexAt(w, v)), po.corner.push_back(v == 0);
  for (uint32_t u = w; u > 0; --u) po.verts.push_back(vertexAt(u, h)), po.corner.push_back(u == w);
  for (uint32_t v = h; v > 0; --v) po.verts.push_back(vertexAt(0, v)), po.corner.push_back(v == h);
  if (!positive) {
    // Reverse the cycle but keep the first vertex first.
    std::reverse(po.verts.begin() + ptrdiff_t(begin) + 1, po.verts.end());
    std::reverse(po.corner.begin() + ptrdiff_t(begin) + 1, po.corner.end());
  }
  po.start.push_back(uint32_t(po.verts.size()));
  po.colors.push_back(color);
}

// Greedy meshing of one plane's n squares e[0, n) (sorted here by key) into rectangles of one colour: from the first
// unused square, the longest row of its colour, then as many rows above it as continue it whole.
PlanePolygons mergePlane(PlaneEntry* const e, size_t n, const std::vector<Square>& sq) {
  std::sort(e, e + n, [](const PlaneEntry& x, const PlaneEntry& y) { return x.key < y.key; });
  std::vector<uint8_t> used(n, 0);
  auto findSquare = [&](size_t from, uint64_t key) -> size_t {
    const PlaneEntry* it =
        std::lower_bound(e + from, e + n, key, [](const PlaneEntry& x, uint64_t k) { return x.key < k; });
    return it != e + n && it->key == key ? size_t(it - e) : n;
  };
  // Square j continues a row at `key` with the same colour, unused.
  auto extends = [&](size_t j, uint64_t key, uint32_t color) {
    return j < n && !used[j] && e[j].key == key && e[j].color == color;
  };
  PlanePolygons po;
  std::vector<size_t> rowStart;
  for (size_t i = 0; i < n; ++i) {
    if (used[i]) continue;
    const uint32_t color = e[i].color;
    uint32_t w = 1;
    while (extends(i + w, e[i].key + w, color)) ++w;
    rowStart.assign(1, i);
    for (;;) {
      const uint64_t rowKey = e[i].key + (uint64_t(rowStart.size()) << 32);
      const size_t j = findSquare(i, rowKey);
      bool ok = j < n;
      for (uint32_t k = 0; k < w && ok; ++k) ok = extends(j + k, rowKey + k, color);
      if (!ok) break;
      rowStart.push_back(j);
    }
    for (size_t r : rowStart) std::fill(used.begin() + ptrdiff_t(r), used.begin() + ptrdiff_t(r + w), 1);
    addRectangle(e, rowStart, w, sq, color, sq[e[i].idx].positive, po);
  }
  return po;
}

// The new ids of the vertices kept (newId[v + 1] > newId[v] when v is kept): those that are a corner of some
// rectangle; the others lie inside a rectangle or straight along the sides of all their rectangles (then they have
// two faces), and dropping them leaves no T-junction. Split lattice points stay: where two sheets run along the same
// lattice line (two voxels meeting along a row of edges), dropping their vertices would give both sheets the same
// long edge, with four faces.
std::vector<uint32_t> keptVertexIds(const std::vector<uint8_t>& split, const std::vector<PlanePolygons>& outs) {
  const size_t nv = split.size();
  std::vector<std::atomic<uint8_t>> keep(nv);
  for (size_t v = 0; v < nv; ++v)
    if (split[v]) keep[v].store(1, std::memory_order_relaxed);
  tbb::parallel_for(size_t(0), outs.size(), [&](size_t pi) {
    const PlanePolygons& po = outs[pi];
    for (size_t k = 0; k < po.verts.size(); ++k)
      if (po.corner[k]) keep[po.verts[k]].store(1, std::memory_order_relaxed);
  });
  std::vector<uint32_t> newId(nv + 1, 0);
  for (size_t v = 0; v < nv; ++v) newId[v + 1] = newId[v] + keep[v].load(std::memory_order_relaxed);
  return newId;
}

// One plane's polygons as faces over the kept vertices (`kv`, renumbered; po.start and po.colors become the faces'):
// a rectangle left with its four corners is one quad; one whose sides still carry vertices becomes triangles without
// zero-area triangles. Polygons with collinear vertices are what MeshLab (2020.09) triangulates into zero-area
// triangles, then reporting non-manifold edges, and what assimp (5.2) fails to triangulate ("no ear found"): issue 10.
void planeFaces(PlanePolygons& po, const std::vector<uint32_t>& newId, const std::vector<Vec3>& positions,
                std::vector<uint32_t>& kv) {
  std::vector<uint32_t> start{0}, colors, poly, tris;
  for (size_t f = 0; f + 1 < po.start.size(); ++f) {
    poly.clear();
    std::array<size_t, 4> corner{};
    size_t corners = 0;
    for (uint32_t k = po.start[f]; k < po.start[f + 1]; ++k) {
      const uint32_t v = po.verts[k];
      if (newId[v + 1] == newId[v]) continue;  // dropped
      if (po.corner[k]) corner[corners++] = poly.size();
      poly.push_back(newId[v]);
    }
    VOX_CHECK(corners == 4 && corner[0] == 0);
    if (poly.size() == 4) {
      kv.insert(kv.end(), poly.begin(), poly.end());
      start.push_back(uint32_t(kv.size()));
      colors.push_back(po.colors[f]);
      continue;
    }
    tris.clear();
    triangulateRectangle(poly, positions, corner, tris);
    for (size_t t = 0; t < tris.size(); t += 3) {
      kv.insert(kv.end(), tris.begin() + ptrdiff_t(t), tris.begin() + ptrdiff_t(t + 3));
      start.push_back(uint32_t(kv.size()));
      colors.push_back(po.colors[f]);
    }
  }
  po.start = std::move(start);
  po.colors = std::move(colors);
}

// The planes' faces one after another into `mesh` (faceStart, faceVertices, faceColors when colored).
void gatherFaces(const std::vector<PlanePolygons>& outs, const std::vector<std::vector<uint32_t>>& kept, bool colored,
                 VoxelMesh& mesh) {
  std::vector<size_t> faceOffset(outs.size() + 1, 0), vertOffset(outs.size() + 1, 0);
  for (size_t pi = 0; pi < outs.size(); ++pi) {
    faceOffset[pi + 1] = faceOffset[pi] + outs[pi].colors.size();
    vertOffset[pi + 1] = vertOffset[pi] + kept[pi].size();
  }
  mesh.faceStart.resize(faceOffset.back() + 1);
  mesh.faceVertices.resize(vertOffset.back());
  if (colored) mesh.faceColors.resize(faceOffset.back());
  mesh.faceStart[0] = 0;
  tbb::parallel_for(size_t(0), outs.size(), [&](size_t pi) {
    std::copy(kept[pi].begin(), kept[pi].end(), mesh.faceVertices.begin() + ptrdiff_t(vertOffset[pi]));
    for (size_t f = 0; f < outs[pi].colors.size(); ++f) {
      mesh.faceStart[faceOffset[pi] + f + 1] = uint32_t(vertOffset[pi] + outs[pi].start[f + 1]);
      if (colored) mesh.faceColors[faceOffset[pi] + f] = unpackColor(outs[pi].colors[f]);
    }
  });
}

VoxelMesh mergedMesh(ExposedSurface&& surface, const std::array<uint32_t, 3>& dims, bool colored) {
  PlaneBuckets buckets = bucketByPlane(surface.squares, dims);
  std::vector<PlanePolygons> outs(buckets.planes.size());
  tbb::parallel_for(size_t(0), buckets.planes.size(), [&](size_t pi) {
    const size_t p = buckets.planes[pi];
    outs[pi] = mergePlane(buckets.order.data() + buckets.planeStart[p],
                          buckets.planeStart[p + 1] - buckets.planeStart[p], surface.squares);
  });
  std::vector<Square>().swap(surface.squares);

  const std::vector<uint32_t> newId = keptVertexIds(surface.split, outs);
  const size_t nv = surface.positions.size();
  VoxelMesh mesh;
  mesh.positions.resize(newId[nv]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      if (newId[v + 1] > newId[v]) mesh.positions[newId[v]] = surface.positions[v];
  });
  std::vector<std::vector<uint32_t>> kept(outs.size());
  tbb::parallel_for(size_t(0), outs.size(), [&](size_t pi) { planeFaces(outs[pi], newId, mesh.positions, kept[pi]); });
  gatherFaces(outs, kept, colored, mesh);
  return mesh;
}

}  // namespace

VoxelMesh buildVoxelMesh(const Grid& grid, const Scene& scene, FaceMode faces, ColorMode color, VoxelMeshStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const Voxels vox = gatherVoxels(grid, scene, color);
  const Lattice lat{grid.bounds, grid.dims};
  const bool colored = color != ColorMode::None;
  VoxelMesh mesh;
  size_t exposed = 0;
  if (faces == FaceMode::All) {
    mesh = buildCubes(vox, lat, colored);
  } else {
    ExposedSurface surface = buildExposed(vox, lat);
    exposed = surface.squares.size();
    mesh = faces == FaceMode::Exposed ? exposedMesh(std::move(surface), colored)
                                      : mergedMesh(std::move(surface), grid.dims, colored);
  }
  if (stats) {
    stats->voxels = vox.keys.size();
    stats->exposedFaces = exposed;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------------------------
// Triangulation.

namespace {

// The axis along which p and q differ (they lie on an axis-parallel line), or -1 if they differ along several.
int segmentAxis(const Vec3& p, const Vec3& q) {
  int axis = -1;
  for (int a = 0; a < 3; ++a)
    if (p[a] != q[a]) {
      if (axis >= 0) return -1;
      axis = a;
    }
  return axis;
}

}  // namespace

std::vector<Rgb8> dominantVertexColors(const VoxelMesh& mesh) {
  if (!mesh.hasColors()) return {};
  const size_t nv = mesh.vertexCount(), nf = mesh.faceCount();
  // Corners grouped by vertex (counting sort), then a small tally per vertex: voxel meshes have a handful of
  // corners per vertex.
  std::vector<uint32_t> cornerStart(nv + 1, 0);
  for (uint32_t v : mesh.faceVertices) ++cornerStart[v + 1];
  for (size_t v = 0; v < nv; ++v) cornerStart[v + 1] += cornerStart[v];
  struct Corner {
    uint32_t color;
    double angle;
  };
  std::vector<Corner> corners(mesh.faceVertices.size());
  {
    std::vector<uint32_t> cursor(cornerStart.begin(), cornerStart.end() - 1);
    for (size_t f = 0; f < nf; ++f) {
      const uint32_t b = mesh.faceStart[f], e = mesh.faceStart[f + 1], n = e - b;
      const uint32_t color = packColor(mesh.faceColors[f]);
      for (uint32_t k = 0; k < n; ++k) {
        const uint32_t u = mesh.faceVertices[b + (k + n - 1) % n], v = mesh.faceVertices[b + k],
                       w = mesh.faceVertices[b + (k + 1) % n];
        const Vec3 a = mesh.positions[u] - mesh.positions[v], c = mesh.positions[w] - mesh.positions[v];
        corners[cursor[v]++] = {color, std::atan2(length(cross(a, c)), dot(a, c))};
      }
    }
  }
  std::vector<Rgb8> colors(nv, Rgb8{255, 255, 255});
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<std::pair<uint32_t, double>> tally;
    for (size_t v = r.begin(); v != r.end(); ++v) {
      tally.clear();
      for (uint32_t k = cornerStart[v]; k < cornerStart[v + 1]; ++k) {
        auto it = std::find_if(tally.begin(), tally.end(), [&](const auto& t) { return t.first == corners[k].color; });
        if (it == tally.end())
          tally.push_back({corners[k].color, corners[k].angle});
        else
          it->second += corners[k].angle;
      }
      if (tally.empty()) continue;
      // Packed as 0x01BBGGRR; compare as (r, g, b) for the documented tie rule.
      auto rgbKey = [](uint32_t c) { return ((c & 0xFF) << 16) | (c & 0xFF00) | ((c >> 16) & 0xFF); };
      auto best = tally.front();
      for (const auto& t : tally)
        if (t.second > best.second || (t.second == best.second && rgbKey(t.first) < rgbKey(best.first))) best = t;
      colors[v] = unpackColor(best.first);
    }
  });
  return colors;
}

VoxelMesh triangulateVoxelMesh(const VoxelMesh& mesh) {
  const size_t nf = mesh.faceCount();
  std::vector<size_t> triStart(nf + 1, 0);
  for (size_t f = 0; f < nf; ++f) triStart[f + 1] = triStart[f] + (mesh.faceSize(f) >= 3 ? mesh.faceSize(f) - 2 : 0);
  VoxelMesh out;
  out.positions = mesh.positions;
  out.faceVertices.resize(3 * triStart[nf]);
  out.faceStart.resize(triStart[nf] + 1);
  if (mesh.hasColors()) out.faceColors.resize(triStart[nf]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nf), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> poly, tris;
    for (size_t f = r.begin(); f != r.end(); ++f) {
      poly.assign(mesh.faceVertices.begin() + mesh.faceStart[f], mesh.faceVertices.begin() + mesh.faceStart[f + 1]);
      const size_t n = poly.size();
      tris.clear();
      std::array<size_t, 4> corner{};
      int corners = 0;
      bool rect = n >= 4;
      for (size_t k = 0; k < n && rect; ++k) {
        const int in = segmentAxis(mesh.positions[poly[(k + n - 1) % n]], mesh.positions[poly[k]]);
        const int outAxis = segmentAxis(mesh.positions[poly[k]], mesh.positions[poly[(k + 1) % n]]);
        if (in < 0 || outAxis < 0)
          rect = false;
        else if (in != outAxis) {
          if (corners == 4)
            rect = false;
          else
            corner[corners++] = k;
        }
      }
      if (rect && corners == 4) {
        triangulateRectangle(poly, mesh.positions, corner, tris);
      } else {
        for (size_t k = 1; k + 1 < n; ++k) tris.insert(tris.end(), {poly[0], poly[k], poly[k + 1]});
      }
      VOX_CHECK(tris.size() == 3 * (triStart[f + 1] - triStart[f]));
      std::copy(tris.begin(), tris.end(), out.faceVertices.begin() + ptrdiff_t(3 * triStart[f]));
      for (size_t t = triStart[f]; t < triStart[f + 1]; ++t) {
        out.faceStart[t + 1] = uint32_t(3 * (t + 1));
        if (mesh.hasColors()) out.faceColors[t] = mesh.faceColors[f];
      }
    }
  });
  return out;
}

uint32_t largestCellCount(const Grid& grid) {
  uint32_t n = 0;
  for (size_t c = 0; c + 1 < grid.cellStart.size(); ++c)
    n = std::max<uint32_t>(n, uint32_t(grid.cellStart[c + 1] - grid.cellStart[c]));
  return n;
}

std::vector<Rgb8> occupiedCellColors(const Grid& grid, const Scene& scene, ColorMode color, uint32_t maxCount) {
  if (color == ColorMode::None) return {};
  const std::vector<uint32_t> packed = occupiedColors(grid, scene, color, maxCount);
  std::vector<Rgb8> colors(packed.size());
  for (size_t c = 0; c < packed.size(); ++c) colors[c] = unpackColor(packed[c]);
  return colors;
}

}  // namespace vox
