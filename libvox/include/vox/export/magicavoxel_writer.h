// MagicaVoxel .vox output (RIFF-style chunks, version 150 with the scene-graph extension; specification:
// github.com/ephtracy/voxel-model, MagicaVoxel-file-format-vox.txt and -vox-extension.txt).
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <span>
#include <vector>

#include "vox/core/grid.h"
#include "vox/export/voxel_mesh.h"

namespace vox {

// A model holds at most 256 voxels per side (coordinates are bytes).
inline constexpr uint32_t kVoxModelSide = 256;

struct MagicaVoxelStats {
  uint64_t voxels = 0;          // voxels written: the grid's occupied and solid cells
  uint32_t models = 0;          // non-empty 256^3 tiles of the grid
  uint32_t gridColors = 0;      // distinct colours among the voxels
  uint32_t paletteColors = 0;   // colours in the palette (<= 255)
  bool paletteReduced = false;  // more than 255 grid colours: each voxel gets the nearest of 255 median-cut colours
};

// Up to 255 palette colours for colours `colors` with weights `weights` (same size, weights > 0): the colours
// themselves, in increasing (r, g, b) order, when there are at most 255; otherwise 255 median-cut boxes (Heckbert
// 1982: split the box of most weighted voxels along its longest channel at the weighted median), each the weighted
// mean of its colours. Never empty when `colors` is not.
std::vector<Rgb8> choosePalette(std::span<const Rgb8> colors, std::span<const uint64_t> weights);

// Writes the voxels of `grid` as a MagicaVoxel file to `out`. The grid is cut into tiles of 256^3 cells; each
// non-empty tile is one model (SIZE and XYZI chunks; voxel (x, y, z) of the model is cell (tile origin + (x, y,
// z))), placed by the scene graph: a root transform over one group holding, per model, a transform node whose
// translation "_t" is tile origin + floor(size / 2) (MagicaVoxel places a model's centre, rounded down, at its
// translation) over a shape node. The grid's axes are kept (MagicaVoxel's z is up: a y-up scene lies on its back).
// Colours: cellColors holds one colour per occupied cell (grid.cellKeys order), or is empty (all voxels
// solidColor); cells that are only solid get solidColor. The palette (RGBA chunk) is choosePalette of the voxels'
// colours weighted by voxel counts; each voxel gets the index of its colour, or of the nearest palette colour.
// Memory: one 256-thick z slab of voxels (4 bytes each) at a time, never the whole grid.
// Throws LimitError when the file would exceed the 2^31 - 1 bytes that the format's int32 chunk sizes allow, or the
// slab does not fit the memory budget; InputError for an inconsistent grid or a cellColors of the wrong size.
MagicaVoxelStats writeMagicaVoxel(std::ostream& out, const Grid& grid, std::span<const Rgb8> cellColors,
                                  Rgb8 solidColor, const std::function<void(double)>& progress = {});

// A grid's voxels in pieces, for writing a grid without holding it: each call hands `visit` every piece in key
// order. A piece is a Grid with the whole grid's dims whose cellKeys (sorted) and solidRuns (checkSolidRuns) all
// come after the previous piece's (a layer of bricks of a grid set: forEachGridSetLayer), with the colours of its
// occupied cells as writeMagicaVoxel's cellColors (one per cell, or none for all-solidColor). Only the keys and runs
// of a piece are read (its cellStart and primIds may be empty).
using ColoredPieceVisitor = std::function<void(const Grid& piece, std::span<const Rgb8> cellColors)>;
using ColoredPieceSource = std::function<void(const ColoredPieceVisitor& visit)>;

// The same file as writeMagicaVoxel of the whole grid, from the plan of the grid (bounds and dims; its cells are not
// read) and a source of its pieces, asked twice (to count the models' voxels and the colours' weights, then to
// write; it must give the same pieces both times). Memory: one piece at a time plus one 256-thick slab of voxels.
// Throws as writeMagicaVoxel, and InputError when the pieces' keys do not ascend from piece to piece.
MagicaVoxelStats writeMagicaVoxelPieces(std::ostream& out, const Grid& plan, const ColoredPieceSource& pieces,
                                        Rgb8 solidColor, const std::function<void(double)>& progress = {});

}  // namespace vox
