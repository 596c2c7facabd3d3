// Cutting an OBJ text into chunks and joining the chunks' readings (obj_chunks.h).
#include "import/obj_chunks.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <unordered_map>
#include <utility>

#include "import/obj_text.h"
#include "vox/core/error.h"
#include "vox/core/huge_pages.h"

namespace vox {
namespace {

// Whether the physical line ending at text[eol] ('\n') continues on the next one (a backslash before the line end,
// after one CR), as LineReader reads it.
bool continuesAt(std::string_view text, size_t eol) {
  size_t end = eol;
  if (end > 0 && text[end - 1] == '\r') --end;
  return end > 0 && text[end - 1] == '\\';
}

// The chunk's physical lines, `v` and `vt` statements and the triangles of its `f` statements (the "before" counts
// of the next chunk), with the words the parser reads.
struct ChunkCounts {
  long long lines = 0;
  size_t vertices = 0;
  size_t texcoords = 0;
  size_t triangles = 0;
};

ChunkCounts countChunk(std::string_view text) {
  ChunkCounts counts;
  LineReader lines(text);
  std::string_view line;
  long long number = 0;
  while (lines.next(line, number)) {
    Words words{line};
    const std::string_view keyword = words.next();
    if (keyword == "v") {
      ++counts.vertices;
    } else if (keyword == "vt") {
      ++counts.texcoords;
    } else if (keyword == "f") {
      size_t corners = 0;
      while (!words.next().empty()) ++corners;
      if (corners >= 3) counts.triangles += corners - 2;  // fewer is an error the parser reports
    }
  }
  counts.lines = lines.physicalLines();
  return counts;
}

// Copies parts[k].data.*member into out at the running offsets, in parallel over the chunks (releasing each).
template <typename T, typename Member>
void joinArrays(std::vector<ObjChunkResult>& parts, Member member, std::vector<T>& out) {
  if (parts.size() == 1) {  // a small file: nothing to copy
    out = std::move(parts[0].data.*member);
    return;
  }
  std::vector<size_t> offset(parts.size() + 1, 0);
  for (size_t k = 0; k < parts.size(); ++k) offset[k + 1] = offset[k] + (parts[k].data.*member).size();
  reserveOnHugePages(out, offset.back());
  out.resize(offset.back());
  tbb::parallel_for(size_t(0), parts.size(), [&](size_t k) {
    const std::vector<T>& from = parts[k].data.*member;
    std::copy(from.begin(), from.end(), out.begin() + std::ptrdiff_t(offset[k]));
    std::vector<T>().swap(parts[k].data.*member);
  });
}

template <typename... Parts>
[[noreturn]] void failAt(const std::string& path, long long line, const Parts&... parts) {
  fail<InputError>(path, ":", line, ": ", parts...);
}

// Numbers every chunk's materials by first use in the file; returns each chunk's local -> global ids.
std::vector<std::vector<uint32_t>> joinMaterials(std::vector<ObjChunkResult>& parts, ObjData& out) {
  std::unordered_map<std::string, uint32_t> ids;
  std::vector<std::vector<uint32_t>> global(parts.size());
  for (size_t k = 0; k < parts.size(); ++k) {
    const ObjData& d = parts[k].data;
    for (size_t m = 0; m < d.materialNames.size(); ++m) {
      const auto [it, added] = ids.try_emplace(d.materialNames[m], uint32_t(out.materialNames.size()));
      if (added) {
        out.materialNames.push_back(d.materialNames[m]);
        out.materialLines.push_back(d.materialLines[m]);
      }
      global[k].push_back(it->second);
    }
  }
  return global;
}

// Each triangle's material as a file-wide id, in place: chunk-local ids mapped, kObjMaterialBefore resolved to the
// material in use where the chunk began.
void joinTriangleMaterials(std::vector<ObjChunkResult>& parts, ObjData& out) {
  const std::vector<std::vector<uint32_t>> global = joinMaterials(parts, out);
  std::vector<uint32_t> atStart(parts.size(), kNoObjMaterial);
  for (size_t k = 1; k < parts.size(); ++k) {
    const uint32_t end = parts[k - 1].materialAtEnd;
    atStart[k] = end == kObjMaterialBefore ? atStart[k - 1] : global[k - 1][end];
  }
  tbb::parallel_for(size_t(0), parts.size(), [&](size_t k) {
    uint32_t* const first = out.triangleMaterial.data() + parts[k].trianglesBefore;
    for (uint32_t* m = first; m != first + parts[k].triangleCount; ++m)
      *m = *m == kObjMaterialBefore ? atStart[k] : global[k][*m];
  });
}

// Texture coordinates per triangle: none when no chunk has them, else one entry per triangle of the file.
void joinTriangleTexcoords(std::vector<ObjChunkResult>& parts, ObjData& out) {
  const bool any = std::any_of(parts.begin(), parts.end(),
                               [](const ObjChunkResult& p) { return !p.data.triangleTexcoords.empty(); });
  if (!any) return;
  constexpr std::array<uint32_t, 3> none = {kNoObjTexcoord, kNoObjTexcoord, kNoObjTexcoord};
  for (ObjChunkResult& p : parts)
    if (p.data.triangleTexcoords.empty()) p.data.triangleTexcoords.assign(p.triangleCount, none);
  joinArrays(parts, &ObjData::triangleTexcoords, out.triangleTexcoords);
}

}  // namespace

std::vector<ObjChunk> cutObjText(std::string_view text, size_t chunkBytes, ImportProgress* progress) {
  std::vector<ObjChunk> chunks;
  size_t begin = 0;
  while (begin < text.size()) {
    size_t end = text.size();
    if (text.size() - begin >= 2 * chunkBytes) {
      size_t eol = text.find('\n', begin + chunkBytes - 1);
      while (eol != std::string_view::npos && continuesAt(text, eol)) eol = text.find('\n', eol + 1);
      if (eol != std::string_view::npos) end = eol + 1;
    }
    chunks.push_back({text.substr(begin, end - begin)});
    begin = end;
  }
  std::vector<ChunkCounts> counts(chunks.size());
  std::atomic<size_t> counted{0};
  tbb::parallel_for(size_t(0), chunks.size(), [&](size_t k) {
    if (progress && progress->cancelled()) return;
    counts[k] = countChunk(chunks[k].text);
    if (progress) progress->report(0.1 + 0.1 * double(++counted) / double(chunks.size()));
  });
  if (progress) progress->check();
  for (size_t k = 0; k < chunks.size(); ++k) {
    chunks[k].vertices = counts[k].vertices;
    chunks[k].triangles = counts[k].triangles;
    if (k == 0) continue;
    chunks[k].linesBefore = chunks[k - 1].linesBefore + counts[k - 1].lines;
    chunks[k].verticesBefore = chunks[k - 1].verticesBefore + counts[k - 1].vertices;
    chunks[k].texcoordsBefore = chunks[k - 1].texcoordsBefore + counts[k - 1].texcoords;
    chunks[k].trianglesBefore = chunks[k - 1].trianglesBefore + counts[k - 1].triangles;
  }
  return chunks;
}

void joinObjChunks(std::vector<ObjChunkResult>& parts, const std::string& path, ObjData& out) {
  const size_t vertexCount = out.vertices.size();
  size_t texcoordCount = 0;
  for (const ObjChunkResult& p : parts) texcoordCount += p.data.texcoords.size();
  // Positive indices may name vertices defined further down; judged now, in file order, as one-piece reading does.
  for (const ObjChunkResult& p : parts)
    for (const ObjForwardIndex& f : p.forward)
      if (f.zeroBased >= vertexCount)
        failAt(path, f.line, "face index ", f.written, " out of range (", vertexCount, " vertices)");
  if (texcoordCount > 0)
    for (const ObjChunkResult& p : parts)
      for (const ObjForwardIndex& f : p.forwardTex)
        if (f.zeroBased >= texcoordCount)
          failAt(path, f.line, "texture coordinate index ", f.written, " out of range (", texcoordCount,
                 " texture coordinates)");

  for (ObjChunkResult& p : parts)
    for (ObjLibrary& lib : p.data.libraries) out.libraries.push_back(std::move(lib));
  size_t unknownCount = 0;
  const ObjChunkResult* firstUnknown = nullptr;
  for (const ObjChunkResult& p : parts) {
    if (p.unknownCount > 0 && !firstUnknown) firstUnknown = &p;
    unknownCount += p.unknownCount;
  }
  if (firstUnknown)
    out.warnings.push_back(path + ": skipped " + std::to_string(unknownCount) +
                           " statements with unknown keywords (first " + quotedWord(firstUnknown->firstUnknown) +
                           " at line " + std::to_string(firstUnknown->firstUnknownLine) + ")");

  joinTriangleMaterials(parts, out);
  if (texcoordCount > 0) joinTriangleTexcoords(parts, out);
  joinArrays(parts, &ObjData::texcoords, out.texcoords);
}

}  // namespace vox
