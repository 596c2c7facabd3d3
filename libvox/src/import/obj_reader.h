// The one Wavefront OBJ / MTL reader of libvox (obj_reader.cpp, obj_chunks.cpp, mtl_reader.cpp, obj_text.cpp),
// shared by the OBJ importer (import_obj.cpp) and the course format's TriangleMesh (import_course.cpp). Numbers are
// read with std::from_chars to the nearest double (never through float); NaN, infinities, out-of-range and malformed
// numbers are refused. Every error is an InputError naming "file:line: ...", the line being the first physical line of
// a statement.
//
// OBJ statements read: `v x y z [more numbers]`, `f a b c ...` (any polygon size, fan-triangulated in linear time;
// forms a, a/t, a//n, a/t/n use the vertex index a; negative indices count back from the vertices read so far;
// positive ones may name vertices defined later in the file), `vt u [v [w]]` (kept as written, v upwards) with the
// face forms a/t and a/t/n (a face's texture coordinates are kept when every corner has one), `usemtl NAME`,
// `mtllib FILE...`. Skipped: `vn`,
// `vp`, `o`, `g`, `s`, `l`, `p`, and any other keyword (counted in one warning). A trailing backslash joins the next
// line; `#` at the start of a word ends the line; CRLF line ends are accepted.
//
// MTL statements read: `newmtl NAME`, `Kd`, `Ks` (one or three numbers), `Ns` (>= 0), `Ni` (> 0; `Ni 0`, which
// exporters write for "unset", keeps 1 with a warning), `map_Kd [options] FILE` (options skipped with their
// arguments; `-clamp on` kept; `-o`, `-s`, `-t` other than their defaults warned as ignored). Other statements are
// skipped.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vox/core/huge_buffer.h"
#include "vox/core/huge_pages.h"
#include "vox/core/math.h"
#include "vox/core/scene.h"
#include "import/import_progress.h"

namespace vox {

// Larger files are refused before they are read (a 4 GiB OBJ holds some 10^8 triangles; 32-bit indices suffice).
constexpr size_t kMaxObjFileBytes = size_t{4} << 30;
constexpr size_t kMaxMtlFileBytes = size_t{64} << 20;

constexpr uint32_t kNoObjMaterial = UINT32_MAX;
constexpr uint32_t kNoObjTexcoord = UINT32_MAX;

struct ObjLibrary {
  std::string name;  // as written after `mtllib`
  long long line = 0;
};

// One OBJ file's geometry. triangles[i] holds 0-based indices into `vertices`, all in range;
// triangleMaterial[i] indexes `materialNames` or is kNoObjMaterial (no `usemtl` before the face).
struct ObjData {
  HugeVector<Vec3> vertices;  // the large arrays on whole huge pages (vox/core/huge_pages.h)
  HugeVector<std::array<uint32_t, 3>> triangles;
  HugeVector<uint32_t> triangleMaterial;
  std::vector<std::string> materialNames;  // `usemtl` names, in order of first use
  std::vector<long long> materialLines;    // the line of each name's first `usemtl`
  std::vector<ObjLibrary> libraries;       // every `mtllib` file name, in file order
  std::vector<TexCoord> texcoords;         // `vt` as written (u, v with v upwards, OBJ's convention)
  // Empty when no face has texture coordinates; else one entry per triangle: indices into `texcoords`, all in
  // range, or kNoObjTexcoord (all three) for a face without them.
  std::vector<std::array<uint32_t, 3>> triangleTexcoords;
  std::vector<std::string> warnings;
};

// `word` quoted for a one-line message: at most 40 characters ("..." after), non-printing bytes as \xHH.
std::string quotedWord(std::string_view word);

// Reads a whole file into memory on huge pages through readInputBytes (input_file.h: regular files only, within
// the memory budget). Throws InputError naming `path` when it cannot be read or is larger than `maxBytes`.
// Reports to `progress` (when given) from 0 to 0.1 of the read.
HugeBuffer readTextFile(const std::string& path, const char* what, size_t maxBytes, ImportProgress* progress = nullptr);

// Texts of at least twice this many bytes are read in chunks of about this size, on all threads (obj_chunks.h).
constexpr size_t kObjChunkBytes = size_t{1} << 19;

// Parses OBJ text; `path` only names the file in messages. Throws InputError "path:line: ..." for the file's first
// error. The result and the error do not depend on chunkBytes (tests read texts in chunks of single lines). Reports
// to `progress` (when given) from 0.1 to 0.9 of the read, a chunk at a time.
ObjData parseObj(std::string_view text, const std::string& path, size_t chunkBytes = kObjChunkBytes,
                 ImportProgress* progress = nullptr);

// A `map_Kd` of material `material` (an index into parseMtl's result): the file as written, its line, `-clamp on`.
struct MtlDiffuseMap {
  size_t material = 0;
  std::string file;
  long long line = 0;
  bool clamp = false;
};

// Parses MTL text into materials in file order (name, diffuse <- Kd, specular <- Ks, exponent <- Ns,
// indexOfRefraction <- Ni; a material starts with diffuse and specular black, exponent 1, index 1).
// Remarks (such as `Ni 0`) are appended to `warnings`. `map_Kd` statements are appended to `maps` when given (a
// material with `map_Kd` and no `Kd` gets diffuse white, so that the texture shows unchanged). Throws InputError
// "path:line: ...".
std::vector<Material> parseMtl(std::string_view text, const std::string& path, std::vector<std::string>& warnings,
                               std::vector<MtlDiffuseMap>* maps = nullptr);

}  // namespace vox
