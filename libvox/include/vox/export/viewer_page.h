// The viewer page of vox-export (DESIGN.md "Viewer page"): one self-contained HTML file holding the grid's data in a
// small binary layout (docs/viewer-format.md), base64-encoded, and the page's script (three.js and viewer/src,
// bundled at build time by viewer/build.mjs). The page reads the layout with viewer/src/data.js; this file writes it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/export/voxel_mesh.h"

namespace vox {

// Version of the binary layout written by encodeViewerData (docs/viewer-format.md); the page refuses another.
inline constexpr uint32_t kViewerDataVersion = 1;
// Size of the fixed header; every array after it starts at a multiple of 8 bytes from the start.
inline constexpr size_t kViewerHeaderBytes = 256;

struct ViewerPageOptions {
  ColorMode color = ColorMode::Count;  // as vox-export --color: the surface, the cut faces and the cell colours
  uint32_t idsPerCell = 4;             // the first primitive ids of each cell kept for the page's cell info
  std::string title;                   // shown by the page (the grid's file name); UTF-8
  // Asked every few milliseconds with the fraction done (from the calling thread, and from worker threads while the
  // surface is built); returning false cancels the write with Error("viewer page cancelled"), the old file kept.
  std::function<bool(double)> progress;
};

// What encodeViewerData wrote, for --stats and tests.
struct ViewerDataStats {
  uint64_t voxels = 0;            // occupied plus solid cells
  uint64_t surfaceVertices = 0;   // lattice points of the merged surface, one per point and colour
  uint64_t surfaceTriangles = 0;  // triangles of the merged surface (the --faces merged mesh, triangulated)
  uint64_t storedIds = 0;         // primitive ids kept (at most idsPerCell per cell)
  uint64_t levelVertices = 0;     // the level surface's (flag bit 10; 0 without one)
  uint64_t levelTriangles = 0;
  uint64_t dataBytes = 0;  // the binary layout
  uint64_t pageBytes = 0;  // the HTML file (writeViewerPage only)
};

// The grid's data as the page reads it (docs/viewer-format.md, version kViewerDataVersion), little-endian:
//  - a 256-byte header: bounds, dims, colour mode, the camera (the scene's, or defaultCamera(grid.bounds) as
//    vox-trace takes it), the background, counts;
//  - the merged exposed surface (buildVoxelMesh FaceMode::Merged, triangulated), its vertices as integer lattice
//    coordinates (vertex (a, b, c) lies at (cellBoundary(x, a), cellBoundary(y, b), cellBoundary(z, c))), split so
//    that every vertex has one colour;
//  - the occupied cells in key order, grouped by row (j, k): each cell's i, primitive count, palette colour and its
//    first min(count, idsPerCell) primitive ids; the solid runs;
//  - the scene's triangles and spheres (float, relative to the bounds' centre), for the page's triangle overlay;
//  - when the grid has them (flags bits 8 and 9), the signed-distance band in the same row form as the occupied
//    cells with each distance as float32, and each occupied cell's volume fraction as float32, which the page's
//    slice plane shows. A grid without them gives the layout it gave before they existed;
//  - when the band holds level 0 (largestSurfaceLevel(grid) >= 0; flag bit 10), the level surface
//    extractLevelSurface(grid, 0) as vox-export --surface writes it: its counts, float positions relative to the
//    bounds' centre and triangles, which the page shows beside the voxels.
// Colours are vox-export's (occupiedCellColors; solid cells kSolidCellColor); ColorMode::None stores none.
// Throws InputError for an inconsistent grid (as buildVoxelMesh), LimitError when a count exceeds the layout's 32-bit
// fields (more than 2^32 - 1 vertices, triangles, cells, band cells or ids, or ny * nz >= 2^32). InputError also
// for a band or fractions that do not fit the grid (keys not ascending or outside it, counts that differ).
std::string encodeViewerData(const Grid& grid, const Scene& scene, const ViewerPageOptions& options,
                             ViewerDataStats* stats = nullptr);

// Whether this build holds the page's script (CMake option VOX_VIEWER, which needs Node.js and npm at build time).
bool viewerPageAvailable();

// The HTML page around `data` (a layout from encodeViewerData): the data base64-encoded in
// <script type="application/x-vox-data"> elements (at most 48 MiB of data each), then the bundled script as an inline
// module. A Content-Security-Policy forbids every fetch, so the page cannot reach the network.
// Throws UsageError when the build has no page script (viewerPageAvailable() is false).
std::string viewerPageHtml(std::string_view data, const std::string& title);

// Writes viewerPageHtml(encodeViewerData(grid, scene, options), options.title) to `path` through a temporary file and
// a rename (OutputFile). Throws as encodeViewerData and viewerPageHtml, OutputError when the file cannot be written.
void writeViewerPage(const std::string& path, const Grid& grid, const Scene& scene, const ViewerPageOptions& options,
                     ViewerDataStats* stats = nullptr);

}  // namespace vox
