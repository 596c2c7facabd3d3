// The parts of the voxel meshes (vox/export/voxel_mesh.h) that their three files share: packed colours, the voxels
// and their lattice (voxel_mesh.cpp), the exposed surface (exposed_surface.cpp) and its merged rectangles
// (merged_mesh.cpp).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/core/resize_in_steps.h"
#include "vox/export/voxel_mesh.h"

namespace vox::voxel_surface {

inline constexpr uint32_t kNoColor = 0;
// Colours are packed as 0x01BBGGRR: the top byte marks "has a colour", so that every colour differs from kNoColor.
inline uint32_t packColor(const Rgb8& c) { return 0x01000000u | c[0] | (uint32_t(c[1]) << 8) | (uint32_t(c[2]) << 16); }
inline Rgb8 unpackColor(uint32_t c) { return {uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)}; }

// Progress and cancellation of one export call (the `progress` of buildVoxelMesh, triangulateVoxelMesh and
// occupiedCellColors), as voxelizeScene and fillSolid do it: the callback gets the fraction done and returning false
// makes the call throw Error("<what> cancelled"). Each phase spans a part of [0, 1]. Parallel loops report after
// every block, blocks being small (parallelFor), and skip the blocks left once told to stop; serial loops on the
// calling thread ask every kStride steps (step). The Python binding looks at Ctrl-C in the callback when the
// calling thread makes it, so the calling thread must make it every few milliseconds of work (docs/python.md).
class ExportProgress {
 public:
  static constexpr uint64_t kStride = 4096;

  // `callback` may be empty, and must outlive this.
  ExportProgress(const std::function<bool(double)>& callback, const char* what) : callback_(callback), what_(what) {}

  // The phases that follow are parts of [from, to] of the call: a function's own phases, placed by its caller.
  void within(double from, double to) {
    outerFrom_ = from;
    outerSpan_ = to - from;
    phase(0, 1);
  }
  // The work that follows covers [from, to] of the current `within` range. Throws when cancelled.
  void phase(double from, double to) {
    check();
    from_ = outerFrom_ + outerSpan_ * from;
    span_ = outerSpan_ * (to - from);
    done_ = 0;
  }
  // From any thread: `count` more of the phase's `total` steps are done. False once the call is cancelled.
  bool advance(uint64_t count, uint64_t total) {
    if (cancelled()) return false;
    if (!callback_) return true;
    const uint64_t done = done_.fetch_add(count, std::memory_order_relaxed) + count;
    if (!callback_(fraction(done, total))) cancelled_ = true;
    return !cancelled();
  }
  // Step i of `total` of a serial loop on the calling thread: asks every kStride steps; throws when cancelled.
  void step(uint64_t i, uint64_t total) {
    if (i % kStride == 0) ask(fraction(i, total));
  }
  // v.resize(n) in steps of 8 MiB, asking between them: a resize zero-fills fresh pages on the calling thread alone,
  // which took 0.4 to 3.4 s for the largest arrays of the bunny at 512^3 on a busy machine. Values as resize gives.
  template <typename T>
  void resize(std::vector<T>& v, size_t n) {
    resizeInSteps(v, n, T{}, [&] { ask(from_); });
  }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  void check() const {
    if (cancelled()) fail<Error>(what_, " cancelled");
  }

  // body(range) over [0, n) on the caller's TBB arena, then throws when cancelled. Blocks of about n / 1024 (at least
  // one step): the automatic partitioner may hand a thread a sixteenth of the loop, a tenth of a second and more in
  // the large phases, during which the calling thread would not report.
  template <typename Body>
  void parallelFor(size_t n, const Body& body) {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, n, std::max<size_t>(1, n / 1024)),
        [&](const tbb::blocked_range<size_t>& r) {
          if (cancelled()) return;
          body(r);
          advance(r.size(), n);
        },
        tbb::simple_partitioner());
    check();
  }

 private:
  // From the calling thread: throws when the callback says stop.
  void ask(double f) {
    if (callback_ && !callback_(f)) cancelled_ = true;
    check();
  }
  double fraction(uint64_t done, uint64_t total) const {
    return std::min(1.0, from_ + span_ * double(done) / double(std::max<uint64_t>(total, 1)));
  }

  const std::function<bool(double)>& callback_;
  const char* what_;
  double outerFrom_ = 0, outerSpan_ = 1;
  double from_ = 0, span_ = 1;
  std::atomic<uint64_t> done_{0};
  std::atomic<bool> cancelled_{false};
};

struct Voxels {
  std::vector<uint64_t> keys;    // sorted, unique
  std::vector<uint32_t> colors;  // packed, kNoColor without colour
};

// The lattice coordinate of cell boundary i on each axis, in world space.
struct Lattice {
  Box bounds;
  std::array<uint32_t, 3> dims;
  Vec3 point(uint64_t i, uint64_t j, uint64_t k) const {
    return {cellBoundary(bounds, dims, 0, int64_t(i)), cellBoundary(bounds, dims, 1, int64_t(j)),
            cellBoundary(bounds, dims, 2, int64_t(k))};
  }
};

inline void checkVertexCount(uint64_t n) {
  if (n >= (uint64_t(1) << 32))
    fail<LimitError>("voxel mesh: ", n, " vertices exceed the 2^32 limit of the mesh formats");
}

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

// The exposed unit squares of the voxels and their vertices (FaceMode::Exposed before it becomes quads): see
// exposed_surface.cpp for how lattice points are split into vertices. Throws LimitError for a grid too large.
// Each reports to `progress` over its current `within` range.
ExposedSurface buildExposed(const Voxels& vox, const Lattice& lat, ExportProgress& progress);
// One quad per exposed square.
VoxelMesh exposedMesh(ExposedSurface&& surface, bool colored, ExportProgress& progress);
// FaceMode::Merged: the squares of each plane merged greedily into rectangles of one colour.
VoxelMesh mergedMesh(ExposedSurface&& surface, const std::array<uint32_t, 3>& dims, bool colored,
                     ExportProgress& progress);

// Triangles (appended to `tris`) of the rectangle `poly` (vertex ids into `pos`) whose sides carry extra vertices;
// corner[k] is the position in poly of its k-th corner. No zero-area triangle.
void triangulateRectangle(const std::vector<uint32_t>& poly, const std::vector<Vec3>& pos,
                          const std::array<size_t, 4>& corner, std::vector<uint32_t>& tris);

}  // namespace vox::voxel_surface
