// Solid fill (DESIGN.md "Solid fill"): marks the empty cells inside the scene's solids as solid, stored as runs.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox {

// How fillSolid decided what is inside.
enum class FillRule : uint8_t {
  // Every triangle edge is shared by an even number of triangles (spheres are closed too): a cell is solid when no
  // 6-connected path of empty cells joins it to the outside of the grid. Exact for a conservative (exact, sat, bbox)
  // voxelization of closed surfaces: the cells inside that meet no surface.
  Enclosed,
  // The mesh has open edges, the voxelization (`center`) leaves gaps in closed surfaces, or user bounds cut the
  // scene (then also each row without a surface cell, decided as a run): the enclosed cells as above, and also the
  // cells of the other empty runs along x (in rows that hold a surface cell) whose centre has a
  // generalized winding number (winding_number.h, spheres counting 1 inside) of magnitude at least
  // kWindingThreshold. Evaluated at both ends of each run; a run whose ends disagree is split by bisection. Most
  // runs are decided through the holes' caps (fill.cpp, HoleCaps), with the same result.
  WindingNumber,
};

// 0.5 is the midpoint between outside (0) and inside (1) of Jacobson et al. 2013; the magnitude is used so that a
// mesh oriented inward (a common scanner output) fills like its outward twin.
inline constexpr double kWindingThreshold = 0.5;

struct FillOptions {
  uint64_t memoryLimitBytes = 16ull << 30;  // scratch beyond this throws LimitError, before allocating
  // Called with a fraction in [0, 1], possibly from worker threads; return false to cancel (throws vox::Error).
  std::function<bool(double)> progress;
  // For tests and comparisons: this rule instead of the one chosen from the mesh; with windingOnly, the
  // WindingNumber rule decides the enclosed runs by winding number too.
  std::optional<FillRule> rule;
  bool windingOnly = false;
  // Grid sets (fillGridSet): occupied cells per slab of whole z planes (a plane is never split), which bounds the
  // fill's scratch memory to about one slab's.
  uint64_t slabCells = uint64_t(1) << 21;
};

struct FillReport {
  FillRule rule = FillRule::Enclosed;
  uint64_t openEdges = 0;    // countOpenEdges of the scene's triangles
  bool leakyMethod = false;  // the grid's method is `center`, whose surfaces have gaps
  // User bounds cut the scene (grid.outsidePrims): the grid's faces are not outside, so the runs that reach them and
  // the rows without a surface cell are decided by winding number too (the WindingNumber rule).
  bool boundsCut = false;
  uint64_t enclosedCells = 0;   // solid because enclosed (both rules)
  uint64_t windingCells = 0;    // solid because of the winding number (WindingNumber rule only)
  uint64_t windingQueries = 0;  // winding numbers of the scene evaluated
  uint64_t capQueries = 0;      // winding numbers of the holes' caps alone evaluated (fill.cpp, HoleCaps)
  uint64_t solidCells = 0;      // enclosedCells + windingCells == grid.solidCount()
  uint64_t emptyCells = 0;      // cells holding no primitive
};

// Sets grid.solidRuns (replacing what it held) from `scene`, the scene `grid` was voxelized from. Works on runs of
// empty cells along x, never on single cells: scratch memory is about 60 bytes per occupied cell plus the
// winding-number tree and the holes' caps (budgeted at 640 bytes per triangle), whatever the grid's dimensions. Work is
// spread over the TBB arena of the caller. Throws LimitError when the scratch memory exceeds options.memoryLimitBytes,
// vox::Error when cancelled. Precondition: grid.cellKeys sorted (as voxelizeScene makes them).
FillReport fillSolid(Grid& grid, const Scene& scene, const FillOptions& options = {});

// fillSolid over a grid given as slabs of whole z planes, for grids whose occupied cells do not fit in memory at once
// (grid sets). The flood's components are joined across slab faces through labels given to the gaps of each slab's
// top plane: pass 1 (`link`, every slab in ascending z) joins them, pass 2 (`fill`, the same slabs again, in the same
// order) decides each slab's runs with the components' final status. Scratch memory is one slab's (fillSolid's for
// its cells) plus one plane's keys and 8 bytes per gap of every slab's top plane. The solid runs, concatenated and
// merged where they touch (appendSolidRun), are fillSolid's for the whole grid, run for run.
struct FillWinding;  // fill.cpp: the winding-number tree and the holes' caps

class SlabFill {
 public:
  // `plan`: bounds, dims and method of the grid (its cells are ignored). Throws LimitError as fillSolid.
  SlabFill(const Grid& plan, const Scene& scene, const FillOptions& options);
  // `keys`: the occupied cells of planes [k0, k1), sorted; k0 is 0 or the previous slab's k1.
  void link(std::span<const uint64_t> keys, uint32_t k0, uint32_t k1);
  // After every plane was linked: the solid runs of planes [k0, k1), sorted. Throws as fillSolid.
  std::vector<CellRun> fill(std::span<const uint64_t> keys, uint32_t k0, uint32_t k1);
  // The counts of the slabs filled so far (the whole grid's once every slab was filled).
  const FillReport& report() const { return report_; }

 private:
  Grid slabGrid(std::span<const uint64_t> keys, uint32_t k0, uint32_t k1);
  FillOptions slabOptions(uint32_t k0, uint32_t k1, bool secondPass) const;
  const std::vector<uint64_t>& labelsBelow() const;  // the labels of the gaps of the current slab's plane below

  Grid plan_;
  FillOptions options_;
  std::shared_ptr<const FillWinding> winding_;  // built once, for every slab; none under the Enclosed rule
  FillReport report_;
  uint32_t nextPlane_ = 0;
  bool filling_ = false;
  size_t slab_ = 0;                               // slabs of the current pass so far
  std::vector<uint64_t> previousPlane_;           // the keys of the previous slab's top plane
  std::vector<std::vector<uint64_t>> topLabels_;  // per slab: the label of each gap of its top plane, 0 outside
  std::vector<uint64_t> labelParent_{0};          // union-find over the labels; 0, the outside, stays a root
};

// One line saying how the fill decided, for the tools' stderr: "closed surface, 389351 solid cells", or
// "|winding number| >= 0.5 (mesh has 223 open edges), 391664 solid cells (0 enclosed, 391664 by winding number,
// 120 evaluations, 3732 of the hole caps alone)".
std::string describeFill(const FillReport& report);
// A warning when the result is suspicious (nothing filled although there is room, or every empty cell filled by
// winding number); empty otherwise.
std::string fillWarning(const FillReport& report);

}  // namespace vox
