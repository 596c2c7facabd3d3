// The exposed surface of the voxels (voxel_surface.h): the unit squares between a voxel and an empty cell, with
// vertices shared.
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
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <numeric>
#include <unordered_map>

#include "export/export_budget.h"
#include "export/voxel_surface.h"
#include "vox/core/checked_math.h"

namespace vox::voxel_surface {

namespace {

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
// An entry of std::unordered_map<uint64_t, uint32_t> with its node and bucket (reserved at twice the entries).
constexpr uint64_t kHashEntryBytes = 48;

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

BrickSet buildBricks(const Voxels& vox, const std::array<uint32_t, 3>& dims, ExportProgress& progress) {
  struct Entry {
    uint64_t brick;
    uint32_t local;
    uint32_t color;
  };
  std::vector<Entry> entries;
  progress.resize(entries, vox.keys.size());
  progress.parallelFor(entries.size(), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const auto ijk = cellIndex(dims, vox.keys[v]);
      entries[v] = {brickKey(ijk[0] >> kBrickBits, ijk[1] >> kBrickBits, ijk[2] >> kBrickBits),
                    uint32_t((ijk[0] & 7) | ((ijk[1] & 7) << 3) | ((ijk[2] & 7) << 6)), vox.colors[v]};
    }
  });
  tbb::parallel_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.brick != b.brick ? a.brick < b.brick : a.local < b.local;
  });
  // The voxel list's estimate (voxel_mesh.cpp) covers the entries and colours; bricks are per 8^3 block touched, up
  // to one per voxel when they are scattered, so they are counted and checked before they are made.
  progress.check();  // the sort cannot stop inside: 0.02 s for the bunny at 512^3 (a million voxels)
  uint64_t nBricks = 0;
  for (size_t v = 0; v < entries.size(); ++v) {
    progress.step(v, entries.size());
    nBricks += v == 0 || entries[v].brick != entries[v - 1].brick;
  }
  requireMemory(saturatingMul(nBricks, sizeof(Brick) + kHashEntryBytes), "voxel mesh",
                std::to_string(nBricks) + " bricks of 8^3 cells");
  BrickSet set;
  set.bricks.reserve(nBricks);
  progress.resize(set.colors, entries.size());
  for (size_t v = 0; v < entries.size(); ++v) {
    progress.step(v, entries.size());
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
  for (uint32_t b = 0; b < set.bricks.size(); ++b) {
    progress.step(b, set.bricks.size());
    set.index.emplace(set.bricks[b].key, b);
  }
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

  // The exposed faces of the brick's own voxels (local cells 0 .. kBrick - 1): faces whose neighbour is empty, the
  // squares brickSquares makes, counted from the rows' bits.
  uint32_t exposedFaces() const {
    const auto bits = [&](int y, int z, int shift) { return (row(y, z) >> (kPadLo + shift)) & 0xFFu; };
    uint32_t n = 0;
    for (int z = 0; z < kBrick; ++z)
      for (int y = 0; y < kBrick; ++y) {
        const uint32_t v = bits(y, z, 0);
        if (!v) continue;
        for (uint32_t neighbour : {bits(y, z, -1), bits(y, z, 1), bits(y - 1, z, 0), bits(y + 1, z, 0),
                                   bits(y, z - 1, 0), bits(y, z + 1, 0)})
          n += uint32_t(std::popcount(v & ~neighbour));
      }
    return n;
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

// The bricks owning lattice points of the voxels' corners, sorted by key: lattice point (i,j,k) belongs to brick
// (i,j,k) >> 3, and the corners of a voxel reach one brick up on each axis.
struct WorkBricks {
  std::vector<uint64_t> keys;
  std::unordered_map<uint64_t, uint32_t> index;  // key -> position in keys
};

WorkBricks workBricks(const BrickSet& set, ExportProgress& progress) {
  requireMemory(saturatingMul(set.bricks.size(), 8 * (sizeof(uint64_t) + kHashEntryBytes)), "voxel mesh",
                "the lattice bricks around " + std::to_string(set.bricks.size()) + " bricks");
  WorkBricks work;
  work.keys.reserve(set.bricks.size() * 8);
  for (const Brick& b : set.bricks) {
    progress.step(work.keys.size() / 8, set.bricks.size());
    const auto c = brickCoords(b.key);
    for (int d = 0; d < 8; ++d)
      work.keys.push_back(
          brickKey(uint64_t(c[0] + (d & 1)), uint64_t(c[1] + ((d >> 1) & 1)), uint64_t(c[2] + (d >> 2))));
  }
  tbb::parallel_sort(work.keys.begin(), work.keys.end());
  work.keys.erase(std::unique(work.keys.begin(), work.keys.end()), work.keys.end());
  work.index.reserve(work.keys.size() * 2);
  for (uint32_t w = 0; w < work.keys.size(); ++w) {
    progress.step(w, work.keys.size());
    work.index.emplace(work.keys[w], w);
  }
  return work;
}

// The vertices' numbers: one vertex per cycle of a lattice point, numbered brick by brick. The vertices of local
// point l of work brick w are base[w] + firstLocal[w][l] up to the next point's first.
struct VertexNumbering {
  std::vector<std::array<uint16_t, 512>> firstLocal;
  std::vector<uint64_t> base;  // one more than the work bricks: base.back() is the vertex count
  uint64_t squares = 0;        // exposed squares of the voxels, counted on the way (Pad::exposedFaces)
  uint32_t count(size_t w, int l) const {
    const uint32_t end = l + 1 < 512 ? firstLocal[w][l + 1] : uint32_t(base[w + 1] - base[w]);
    return end - firstLocal[w][l];
  }
};

VertexNumbering numberVertices(const BrickSet& set, const WorkBricks& work, const PointTables& tables,
                               ExportProgress& progress) {
  const size_t nWork = work.keys.size();
  requireMemory(saturatingMul(nWork, sizeof(std::array<uint16_t, 512>) + sizeof(uint64_t)), "voxel mesh",
                "the vertex numbers of " + std::to_string(nWork) + " lattice bricks");
  VertexNumbering num;
  progress.resize(num.firstLocal, nWork);
  num.base.assign(nWork + 1, 0);
  std::atomic<uint64_t> squares{0};
  progress.parallelFor(nWork, [&](const tbb::blocked_range<size_t>& r) {
    Pad pad;
    uint64_t rangeSquares = 0;
    for (size_t w = r.begin(); w != r.end(); ++w) {
      const auto bc = brickCoords(work.keys[w]);
      pad.fill(set, bc[0], bc[1], bc[2]);
      if (set.index.count(work.keys[w])) rangeSquares += pad.exposedFaces();
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
    squares += rangeSquares;
  });
  num.squares = squares;
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
std::vector<Square> concatenate(std::vector<std::vector<Square>>& lists, ExportProgress& progress) {
  std::vector<size_t> offset(lists.size() + 1, 0);
  for (size_t w = 0; w < lists.size(); ++w) offset[w + 1] = offset[w] + lists[w].size();
  std::vector<Square> all;
  progress.resize(all, offset.back());
  progress.parallelFor(lists.size(), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t w = r.begin(); w != r.end(); ++w) {
      std::copy(lists[w].begin(), lists[w].end(), all.begin() + ptrdiff_t(offset[w]));
      std::vector<Square>().swap(lists[w]);
    }
  });
  return all;
}

}  // namespace

ExposedSurface buildExposed(const Voxels& vox, const Lattice& lat, ExportProgress& progress) {
  const PointTables& tables = pointTables();
  for (int a = 0; a < 3; ++a)
    if (lat.dims[a] >= (uint32_t(1) << (kKeyBits + kBrickBits)) - 2 * kBrick)
      fail<LimitError>("voxel mesh: grid dimension ", lat.dims[a], " too large for export");
  // The shares of the phases: about their times for the bunny at 512^3.
  progress.phase(0, 0.2);
  const BrickSet set = buildBricks(vox, lat.dims, progress);
  progress.phase(0.2, 0.25);
  const WorkBricks work = workBricks(set, progress);
  const size_t nWork = work.keys.size();
  progress.phase(0.25, 0.55);
  const VertexNumbering num = numberVertices(set, work, tables, progress);

  requireMemory(saturatingMul(num.base[nWork], sizeof(Vec3) + 1), "voxel mesh",
                std::to_string(num.base[nWork]) + " vertices");
  // The squares are made per brick and then copied into one array (each brick's list freed as it is copied):
  // twice their size at the peak. A row of solid cells has four squares a cell, so this is not bounded by the voxel
  // list's estimate.
  requireMemory(saturatingMul(num.squares, 2 * sizeof(Square)), "voxel mesh",
                std::to_string(num.squares) + " exposed squares");
  ExposedSurface out;
  progress.resize(out.positions, num.base[nWork]);
  progress.resize(out.split, num.base[nWork]);
  std::vector<std::vector<Square>> perBrick(nWork);
  progress.phase(0.55, 0.9);
  progress.parallelFor(nWork, [&](const tbb::blocked_range<size_t>& r) {
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
  progress.phase(0.9, 1);
  out.squares = concatenate(perBrick, progress);
  VOX_CHECK(out.squares.size() == num.squares);
  return out;
}

VoxelMesh exposedMesh(ExposedSurface&& surface, bool colored, ExportProgress& progress) {
  VoxelMesh mesh;
  mesh.positions = std::move(surface.positions);
  const size_t n = surface.squares.size();
  progress.resize(mesh.faceStart, n + 1);
  progress.resize(mesh.faceVertices, 4 * n);
  if (colored) progress.resize(mesh.faceColors, n);
  progress.parallelFor(n, [&](const tbb::blocked_range<size_t>& r) {
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

}  // namespace vox::voxel_surface
