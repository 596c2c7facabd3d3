// FaceMode::Merged (voxel_surface.h): greedy meshing of each plane's exposed squares into rectangles of one colour,
// and rectangles with extra vertices on their sides as triangles.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>

#include "export/voxel_surface.h"

namespace vox::voxel_surface {

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

namespace {

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

PlaneBuckets bucketByPlane(const std::vector<Square>& sq, const std::array<uint32_t, 3>& dims,
                           ExportProgress& progress) {
  std::array<size_t, 4> axisBase{};
  for (int a = 0; a < 3; ++a) axisBase[a + 1] = axisBase[a] + 2 * (size_t(dims[a]) + 1);
  const size_t nPlanes = axisBase[3];
  auto planeOf = [&](const Square& s) { return axisBase[s.axis] + 2 * size_t(s.plane) + s.positive; };
  PlaneBuckets out;
  out.planeStart.assign(nPlanes + 1, 0);
  for (size_t i = 0; i < sq.size(); ++i) {
    progress.step(i, 2 * sq.size());
    ++out.planeStart[planeOf(sq[i]) + 1];
  }
  for (size_t p = 0; p < nPlanes; ++p) out.planeStart[p + 1] += out.planeStart[p];
  progress.resize(out.order, sq.size());
  std::vector<uint32_t> cursor(out.planeStart.begin(), out.planeStart.end() - 1);
  for (uint32_t i = 0; i < sq.size(); ++i) {
    progress.step(sq.size() + i, 2 * sq.size());
    out.order[cursor[planeOf(sq[i])]++] = {(uint64_t(sq[i].v) << 32) | sq[i].u, sq[i].color, i};
  }
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
std::vector<uint32_t> keptVertexIds(const std::vector<uint8_t>& split, const std::vector<PlanePolygons>& outs,
                                    ExportProgress& progress) {
  const size_t nv = split.size();
  std::vector<std::atomic<uint8_t>> keep(nv);
  for (size_t v = 0; v < nv; ++v) {
    progress.step(v, 2 * nv);
    if (split[v]) keep[v].store(1, std::memory_order_relaxed);
  }
  progress.parallelFor(outs.size(), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t pi = r.begin(); pi != r.end(); ++pi) {
      const PlanePolygons& po = outs[pi];
      for (size_t k = 0; k < po.verts.size(); ++k)
        if (po.corner[k]) keep[po.verts[k]].store(1, std::memory_order_relaxed);
    }
  });
  std::vector<uint32_t> newId;
  progress.resize(newId, nv + 1);
  for (size_t v = 0; v < nv; ++v) {
    progress.step(nv + v, 2 * nv);
    newId[v + 1] = newId[v] + keep[v].load(std::memory_order_relaxed);
  }
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
                 VoxelMesh& mesh, ExportProgress& progress) {
  std::vector<size_t> faceOffset(outs.size() + 1, 0), vertOffset(outs.size() + 1, 0);
  for (size_t pi = 0; pi < outs.size(); ++pi) {
    faceOffset[pi + 1] = faceOffset[pi] + outs[pi].colors.size();
    vertOffset[pi + 1] = vertOffset[pi] + kept[pi].size();
  }
  progress.resize(mesh.faceStart, faceOffset.back() + 1);
  progress.resize(mesh.faceVertices, vertOffset.back());
  if (colored) progress.resize(mesh.faceColors, faceOffset.back());
  mesh.faceStart[0] = 0;
  progress.parallelFor(outs.size(), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t pi = r.begin(); pi != r.end(); ++pi) {
      std::copy(kept[pi].begin(), kept[pi].end(), mesh.faceVertices.begin() + ptrdiff_t(vertOffset[pi]));
      for (size_t f = 0; f < outs[pi].colors.size(); ++f) {
        mesh.faceStart[faceOffset[pi] + f + 1] = uint32_t(vertOffset[pi] + outs[pi].start[f + 1]);
        if (colored) mesh.faceColors[faceOffset[pi] + f] = unpackColor(outs[pi].colors[f]);
      }
    }
  });
}

}  // namespace

VoxelMesh mergedMesh(ExposedSurface&& surface, const std::array<uint32_t, 3>& dims, bool colored,
                     ExportProgress& progress) {
  // The shares of the phases: about their times for the bunny at 512^3.
  progress.phase(0, 0.15);
  PlaneBuckets buckets = bucketByPlane(surface.squares, dims, progress);
  std::vector<PlanePolygons> outs(buckets.planes.size());
  progress.phase(0.15, 0.55);
  // One plane a step: a plane holds at most a grid side squared of squares, milliseconds of work.
  progress.parallelFor(buckets.planes.size(), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t pi = r.begin(); pi != r.end(); ++pi) {
      const size_t p = buckets.planes[pi];
      outs[pi] = mergePlane(buckets.order.data() + buckets.planeStart[p],
                            buckets.planeStart[p + 1] - buckets.planeStart[p], surface.squares);
    }
  });
  std::vector<Square>().swap(surface.squares);

  progress.phase(0.55, 0.7);
  const std::vector<uint32_t> newId = keptVertexIds(surface.split, outs, progress);
  const size_t nv = surface.positions.size();
  VoxelMesh mesh;
  progress.resize(mesh.positions, newId[nv]);
  progress.phase(0.7, 0.75);
  progress.parallelFor(nv, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      if (newId[v + 1] > newId[v]) mesh.positions[newId[v]] = surface.positions[v];
  });
  std::vector<std::vector<uint32_t>> kept(outs.size());
  progress.phase(0.75, 0.9);
  progress.parallelFor(outs.size(), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t pi = r.begin(); pi != r.end(); ++pi) planeFaces(outs[pi], newId, mesh.positions, kept[pi]);
  });
  progress.phase(0.9, 1);
  gatherFaces(outs, kept, colored, mesh, progress);
  return mesh;
}

}  // namespace vox::voxel_surface
