// Voxel meshes: the voxels of a grid (occupied and solid cells) as a polygon mesh, for vox-export (DESIGN.md,
// "vox-export"). Building is pure geometry (voxel_mesh.cpp, exposed_surface.cpp, merged_mesh.cpp); writing lives in
// export_mesh.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

enum class FaceMode : uint8_t {
  All,      // one closed cube per voxel: 8 own vertices, 12 triangles
  Exposed,  // unit squares between a voxel and an empty cell (or the outside), vertices shared: closed, 2-manifold
  Merged,   // the exposed squares merged into same-coloured rectangles (quads, or triangles where sides carry
            // vertices): closed, 2-manifold, no T-junctions
};
enum class ColorMode : uint8_t {
  Count,     // countColor(primitives in the cell, largest count in the grid)
  Material,  // diffuse colour of the material held by most of the cell's primitives (ties: lowest material index)
  None,
};

// Throw InputError naming the accepted values for an unknown name.
FaceMode parseFaceMode(const std::string& name);
ColorMode parseColorMode(const std::string& name);
std::string faceModeName(FaceMode mode);
std::string colorModeName(ColorMode mode);

using Rgb8 = std::array<uint8_t, 3>;

// Colour of solid cells (vox-voxelize --fill): they hold no primitive, so neither count nor material applies.
inline constexpr Rgb8 kSolidCellColor{153, 153, 153};

// The display colour of each occupied cell (grid.cellKeys order) under `color`, as buildVoxelMesh paints its faces
// (for the voxel formats, which colour cells rather than faces); empty for ColorMode::None. Count: the ramp ends
// at `maxCount`, 0 meaning largestCellCount(grid); a piece of a larger grid (a layer of a grid set) passes the whole
// grid's, so its cells get the whole grid's colours. Count reads only cellStart, so primIds may be empty
// (LayerCells::KeysAndCounts). Throws InputError like buildVoxelMesh for an inconsistent cell table or a primitive
// or material out of range. `progress` as buildVoxelMesh's (Error "cell colours cancelled").
std::vector<Rgb8> occupiedCellColors(const Grid& grid, const Scene& scene, ColorMode color, uint32_t maxCount = 0,
                                     const std::function<bool(double)>& progress = {});

// The largest number of primitives in one occupied cell of `grid` (from cellStart only); 0 without cells.
uint32_t largestCellCount(const Grid& grid);

// A polygon mesh of plain arrays. Positions are world space (the grid's frame), on the grid lattice given by
// cellBoundary. Face f has the vertices faceVertices[faceStart[f] .. faceStart[f+1]), counter-clockwise seen from
// outside the voxels (so normals point out of the voxels). faceColors is empty (no colour) or holds one 8-bit
// display colour per face (sRGB-encoded, as PLY/OBJ/OFF readers expect).
struct VoxelMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> faceStart{0};
  std::vector<uint32_t> faceVertices;
  std::vector<Rgb8> faceColors;

  size_t vertexCount() const { return positions.size(); }
  size_t faceCount() const { return faceStart.size() - 1; }
  size_t faceSize(size_t f) const { return faceStart[f + 1] - faceStart[f]; }
  bool hasColors() const { return !faceColors.empty(); }
  bool isTriangleMesh() const { return faceVertices.size() == 3 * faceCount(); }
};

struct VoxelMeshStats {
  size_t voxels = 0;        // occupied plus solid cells
  size_t exposedFaces = 0;  // unit squares of the exposed surface (Exposed and Merged; 0 for All)
  double seconds = 0;       // time in buildVoxelMesh
};

// Builds the voxel mesh of `grid`. A voxel is a cell listed in grid.cellKeys (occupied) or grid.solidRuns (solid).
// `scene` supplies the materials for ColorMode::Material (primitive ids as in scene.h); it is not read otherwise.
//  - All: 8 vertices and 12 triangles per voxel, in the order of the voxels' keys.
//  - Exposed: one quad per exposed unit square. Where voxels meet only along an edge or at a corner, lattice points
//    get one vertex per sheet of surface through them, so that every edge has exactly two faces and every vertex a
//    single fan. At an edge with two diagonal voxels and two diagonal empty cells the voxels are kept apart, unless
//    they are joined by face-adjacent voxels around both ends of the edge (then the empty cells are kept apart:
//    the other choice would put four faces on one edge).
//  - Merged: the exposed squares of each plane and orientation merged greedily into rectangles of one colour.
//    A rectangle's sides hold every vertex of the mesh that lies on them, so there is no T-junction; vertices that
//    are a corner of no rectangle are dropped. A rectangle with only its four corners is one quad; one with more
//    vertices on its sides is written as triangles (n vertices: n - 2 triangles, none of zero area), because
//    clients triangulate polygons with collinear vertices badly (MeshLab into zero-area triangles, assimp not at
//    all). So every face is a triangle or a rectangle, and there are at most two triangles' worth per square.
// Colours: per voxel face, from `color`; solid cells get kSolidCellColor. In Merged mode only faces of equal 8-bit
// colour merge. Memory and time grow with the number of voxels, not with the grid's dimensions. Work is spread over
// the TBB arena of the caller. Throws InputError when a cell key lies outside the grid or a primitive id or
// material index is out of range, LimitError when the mesh would need more than 2^32 vertices.
// `progress` (may be empty) is called with the fraction done in [0, 1], from worker threads and from the calling
// thread, the latter at least every few milliseconds of work; return false to cancel (throws vox::Error "voxel mesh
// cancelled").
VoxelMesh buildVoxelMesh(const Grid& grid, const Scene& scene, FaceMode faces, ColorMode color,
                         VoxelMeshStats* stats = nullptr, const std::function<bool(double)>& progress = {});

// A copy of `mesh` with every face split into triangles, without new vertices and without zero-area triangles.
// Precondition: each face is a triangle, or a planar axis-aligned rectangle whose sides may carry extra collinear
// vertices (what buildVoxelMesh produces). Colours follow their faces. `progress` as buildVoxelMesh's (Error
// "triangulation cancelled").
VoxelMesh triangulateVoxelMesh(const VoxelMesh& mesh, const std::function<bool(double)>& progress = {});

// One colour per vertex for clients that read vertex colours only (Blender's and assimp's PLY importers): the face
// colour that covers the largest angle around the vertex (ties: the smallest colour, as bytes r, g, b), so that a
// vertex inside a region of one colour gets exactly that colour and the mesh keeps its shared vertices. Empty
// when the mesh has no colours. Precondition: every face has at least three vertices.
std::vector<Rgb8> dominantVertexColors(const VoxelMesh& mesh);

// Mesh file formats, chosen by the extension of the output path (case-insensitive).
enum class MeshFormat : uint8_t { Ply, Obj, Off, Stl, Glb, Gltf };
// Throws InputError naming the path for an unknown extension.
MeshFormat meshFormatFromPath(const std::string& path);

// Writes `mesh` to `path` in the format of its extension, through a temporary file and a rename (writeAtomically):
// Every format keeps the mesh's shared vertices (no seam is cut along colour boundaries):
//  - .ply (OpenMesh; binary little-endian unless binary is false): the faces, per-face uchar colours (MeshLab) and
//    per-vertex uchar colours from dominantVertexColors (Blender and assimp read vertex colours only).
//  - .off (ASCII, "OFF" header): the faces, each followed by its colour as three integers 0..255.
//  - .obj (ASCII): the faces; with colours, grouped by "usemtl vox_RRGGBB" under "mtllib NAME.mtl", and NAME.mtl
//    (the output's name with the extension .mtl) written beside it, Kd the sRGB display colour in [0, 1]. An OBJ
//    written to a character device or FIFO gets no .mtl.
//  - .stl (OpenMesh; binary unless binary is false): triangles, no colour.
//  - .glb, .gltf (tinygltf; buffers embedded): one POSITION accessor shared by one triangle primitive per colour,
//    each with a matte material whose baseColorFactor is the colour made linear; viewers compute flat normals.
// Throws InputError for an unknown extension, OutputError when the file cannot be written. `progress` (may be
// empty) is asked every megabyte of text and every 65,536th vertex and face of PLY and STL; returning false cancels
// with Error("PATH: writing cancelled"), no file left.
void writeVoxelMesh(const std::string& path, const VoxelMesh& mesh, bool binary = true,
                    const std::function<bool(double)>& progress = {});

}  // namespace vox
