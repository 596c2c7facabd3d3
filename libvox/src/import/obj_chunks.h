// Reading a large OBJ text on all threads (issue 26: 200 MB/s per thread). The text is cut into chunks at the ends of
// logical lines; one quick pass counts each chunk's physical lines, `v` and `vt` statements, so that every chunk then
// parses by itself with the file's line numbers and resolves negative indices against the vertices before it, as a
// one-pass reading would. The chunks' results are joined in file order: materials numbered by first use, the first
// error of the file reported, forward indices judged once all vertices are known. The result is the same ObjData,
// and the same first error, as reading the text in one piece.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "import/obj_reader.h"

namespace vox {

// A chunk of an OBJ text, what its parse needs to know of the text before it, and where its vertices and triangles
// go in the file's arrays: each chunk writes its own part of them, so that nothing is copied when the chunks are
// joined and no array is grown (a growing array is fresh memory each time it moves: docs/voxelize-speed.md).
struct ObjChunk {
  std::string_view text;
  long long linesBefore = 0;   // physical lines
  size_t verticesBefore = 0;   // `v` statements
  size_t texcoordsBefore = 0;  // `vt` statements
  size_t trianglesBefore = 0;  // triangles of `f` statements (a face of n corners makes n - 2)
  size_t vertices = 0;         // the chunk's own `v` statements
  size_t triangles = 0;        // and triangles; exact for a text that reads without error
};

// Chunks of about chunkBytes (the whole text in one below 2 * chunkBytes), each ending where a logical line ends,
// every one counted. Counting runs in parallel, reporting to `progress` (when given) from 0.1 to 0.2 of the read.
std::vector<ObjChunk> cutObjText(std::string_view text, size_t chunkBytes, ImportProgress* progress = nullptr);

// A face's material before any `usemtl` in its chunk: the one in use where the previous chunk ended.
constexpr uint32_t kObjMaterialBefore = UINT32_MAX - 1;

// A face index naming a vertex (or texture coordinate) not yet read where it is written: judged at the end.
struct ObjForwardIndex {
  uint32_t zeroBased;
  long long line;
  long long written;
};

// One chunk's reading. `data` as parseObj's, except: the file's triangleMaterial holds, over the chunk's triangles,
// indices into this chunk's data.materialNames (in this chunk's order of first use) or kObjMaterialBefore;
// triangleTexcoords is empty or holds one entry per triangle of the chunk; data.warnings is empty (unknown keywords
// are counted here instead).
struct ObjChunkResult {
  ObjData data;  // vertices, triangles and triangleMaterial stay empty: the chunk writes them into the file's
  size_t trianglesBefore = 0;
  size_t triangleCount = 0;
  uint32_t materialAtEnd = kObjMaterialBefore;
  std::vector<ObjForwardIndex> forward;
  std::vector<ObjForwardIndex> forwardTex;
  size_t unknownCount = 0;
  std::string firstUnknown;
  long long firstUnknownLine = 0;
};

// Joins the chunks' results into `out`, whose vertices, triangles and triangleMaterial the chunks wrote, in file
// order (materials renumbered in place, texture coordinates copied, in parallel); throws InputError "path:line: ..."
// for the first out-of-range forward index, vertex indices before texture coordinate ones, as one-piece reading
// does.
void joinObjChunks(std::vector<ObjChunkResult>& parts, const std::string& path, ObjData& out);

}  // namespace vox
