// The OBJ reader (obj_reader.h). Each chunk of the text (obj_chunks.h) is read in one pass, every face resolved
// and triangulated as it is read, so the cost is linear in the file size whatever the polygon sizes; large texts are
// read on all threads, chunk by chunk.
#include "import/obj_reader.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <string>
#include <unordered_map>
#include <utility>

#include "import/obj_chunks.h"
#include "import/obj_text.h"
#include "vox/core/error.h"
#include "vox/core/huge_pages.h"
#include "vox/core/memory_budget.h"

namespace vox {
namespace {

class ObjParser {
 public:
  // Writes the chunk's vertices, triangles and their materials into `file`'s arrays, sized by the counting pass.
  ObjParser(const ObjChunk& chunk, const std::string& path, ObjData& file)
      : lines_(chunk.text, chunk.linesBefore),
        path_(path),
        verticesBefore_(chunk.verticesBefore),
        texcoordsBefore_(chunk.texcoordsBefore),
        vertexCapacity_(chunk.vertices),
        triangleCapacity_(chunk.triangles),
        vertices_(file.vertices.data() + chunk.verticesBefore),
        triangles_(file.triangles.data() + chunk.trianglesBefore),
        materials_(file.triangleMaterial.data() + chunk.trianglesBefore) {
    out_.trianglesBefore = chunk.trianglesBefore;
  }

  ObjChunkResult run() {
    std::string_view line;
    long long number = 0;
    while (lines_.next(line, number)) statement(Words{line}, number);
    // The counting pass reads the same words; a difference would be a bug in one of them, not in the file.
    if (vertexCount_ != vertexCapacity_ || out_.triangleCount != triangleCapacity_)
      fail<Error>(path_, ": the OBJ reader counted ", vertexCapacity_, " vertices and ", triangleCapacity_,
                  " triangles in a chunk but read ", vertexCount_, " and ", out_.triangleCount, " (a bug in libvox)");
    return std::move(out_);
  }

 private:
  template <typename... Parts>
  [[noreturn]] void failAt(long long line, const Parts&... parts) const {
    fail<InputError>(path_, ":", line, ": ", parts...);
  }

  void statement(Words words, long long line) {
    const std::string_view keyword = words.next();
    if (keyword.empty()) return;
    if (keyword == "v") {
      vertex(words, line);
    } else if (keyword == "f") {
      face(words, line);
    } else if (keyword == "vt") {
      texcoord(words, line);
    } else if (keyword == "usemtl") {
      useMaterial(words.name(), line);
    } else if (keyword == "mtllib") {
      for (std::string_view w = words.next(); !w.empty(); w = words.next())
        data_.libraries.push_back({std::string(w), line});
    } else if (keyword == "vn" || keyword == "vp" || keyword == "o" || keyword == "g" || keyword == "s" ||
               keyword == "l" || keyword == "p") {
      // Texture coordinates, normals, names, smoothing groups, lines and points: nothing a voxelizer uses.
    } else if (out_.unknownCount++ == 0) {
      out_.firstUnknown = std::string(keyword);
      out_.firstUnknownLine = line;
    }
  }

  void vertex(Words& words, long long line) {
    double xyz[3];
    for (double& c : xyz) {
      const std::string_view w = words.next();
      if (w.empty()) failAt(line, "vertex needs 3 coordinates");
      if (!parseObjNumber(w, c)) failAt(line, "bad number ", quotedWord(w));
    }
    // A fourth number (w) or a colour (r g b) may follow: checked, not kept.
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      double ignored = 0;
      if (!parseObjNumber(w, ignored)) failAt(line, "bad number ", quotedWord(w));
    }
    if (vertexCount_ == vertexCapacity_) failAt(line, "more vertices than counted (a bug in libvox)");
    vertices_[vertexCount_++] = {xyz[0], xyz[1], xyz[2]};
  }

  // `vt u [v [w]]`: u and v kept exactly as written.
  void texcoord(Words& words, long long line) {
    double uvw[3] = {0, 0, 0};
    int n = 0;
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      if (n == 3) failAt(line, "vt takes at most 3 numbers");
      if (!parseObjNumber(w, uvw[n++])) failAt(line, "bad number ", quotedWord(w));
    }
    if (n == 0) failAt(line, "vt needs a number");
    data_.texcoords.push_back({uvw[0], uvw[1]});
  }

  // The 0-based texture coordinate index written `t` in a face corner, or kNoObjTexcoord when empty.
  uint32_t texcoordIndex(std::string_view t, std::string_view word, long long line) {
    if (t.empty()) return kNoObjTexcoord;
    long long i = 0;
    const IntegerStatus status = parseObjInteger(t, i);
    if (status == IntegerStatus::Bad) failAt(line, "bad face index ", quotedWord(word));
    const long long seen = static_cast<long long>(texcoordsBefore_ + data_.texcoords.size());
    const long long zeroBased = i > 0 ? i - 1 : seen + i;
    // Judged at the end: a file without any `vt` has its texture indices ignored, as they always were.
    if (status == IntegerStatus::TooLarge || i == 0 || zeroBased < 0 ||
        zeroBased >= static_cast<long long>(UINT32_MAX)) {
      out_.forwardTex.push_back({kNoObjTexcoord, line, i});
      return 0;
    }
    if (zeroBased >= seen) out_.forwardTex.push_back({static_cast<uint32_t>(zeroBased), line, i});
    return static_cast<uint32_t>(zeroBased);
  }

  // The 0-based vertex index of one face corner `a`, `a/t`, `a//n` or `a/t/n`; `tex` gets t's index.
  uint32_t faceIndex(std::string_view word, long long line, uint32_t& tex) {
    const size_t slash = word.find('/');
    const std::string_view head = word.substr(0, slash);
    tex = kNoObjTexcoord;
    if (slash != std::string_view::npos) {
      std::string_view tail = word.substr(slash + 1);
      for (int part = 0; part < 2; ++part) {
        const size_t next = tail.find('/');
        const std::string_view index = tail.substr(0, next);
        long long ignored = 0;
        if (!index.empty() && parseObjInteger(index, ignored) == IntegerStatus::Bad)
          failAt(line, "bad face index ", quotedWord(word));
        if (part == 0) tex = texcoordIndex(index, word, line);
        if (next == std::string_view::npos) break;
        if (part == 1) failAt(line, "bad face index ", quotedWord(word));
        tail = tail.substr(next + 1);
      }
    }
    long long i = 0;
    const IntegerStatus status = parseObjInteger(head, i);
    const long long seen = static_cast<long long>(verticesBefore_ + vertexCount_);
    if (status == IntegerStatus::Bad) failAt(line, "bad face index ", quotedWord(word));
    if (status == IntegerStatus::TooLarge)
      failAt(line, "face index ", quotedWord(head), " out of range (", seen, " vertices)");
    const long long zeroBased = i > 0 ? i - 1 : seen + i;
    // No file within kMaxObjFileBytes holds 2^32 - 1 vertices, so such an index can never be valid.
    if (i == 0 || zeroBased < 0 || zeroBased >= static_cast<long long>(UINT32_MAX))
      failAt(line, "face index ", i, " out of range (", seen, " vertices)");
    if (zeroBased >= seen) out_.forward.push_back({static_cast<uint32_t>(zeroBased), line, i});
    return static_cast<uint32_t>(zeroBased);
  }

  void face(Words& words, long long line) {
    polygon_.clear();
    polygonTex_.clear();
    bool textured = true;
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      uint32_t tex = kNoObjTexcoord;
      polygon_.push_back(faceIndex(w, line, tex));
      polygonTex_.push_back(tex);
      textured &= tex != kNoObjTexcoord;
    }
    if (polygon_.size() < 3) failAt(line, "face needs at least 3 vertices");
    if (polygon_.size() - 2 > triangleCapacity_ - out_.triangleCount)
      failAt(line, "more triangles than counted (a bug in libvox)");
    for (size_t k = 1; k + 1 < polygon_.size(); ++k) {
      const size_t t = out_.triangleCount++;
      triangles_[t] = {polygon_[0], polygon_[k], polygon_[k + 1]};
      materials_[t] = currentMaterial_;
      if (textured) {
        // Texture coordinates appear with the first face that has them; earlier faces get none.
        data_.triangleTexcoords.resize(t, {kNoObjTexcoord, kNoObjTexcoord, kNoObjTexcoord});
        data_.triangleTexcoords.push_back({polygonTex_[0], polygonTex_[k], polygonTex_[k + 1]});
      } else if (!data_.triangleTexcoords.empty()) {
        data_.triangleTexcoords.push_back({kNoObjTexcoord, kNoObjTexcoord, kNoObjTexcoord});
      }
    }
  }

  void useMaterial(std::string_view name, long long line) {
    if (name.empty()) failAt(line, "usemtl needs a material name");
    const auto [it, added] =
        materialIds_.try_emplace(std::string(name), static_cast<uint32_t>(data_.materialNames.size()));
    if (added) {
      data_.materialNames.push_back(it->first);
      data_.materialLines.push_back(line);
    }
    currentMaterial_ = it->second;
  }

  LineReader lines_;
  const std::string& path_;
  const size_t verticesBefore_;
  const size_t texcoordsBefore_;
  const size_t vertexCapacity_;
  const size_t triangleCapacity_;
  Vec3* const vertices_;  // the chunk's part of the file's arrays
  std::array<uint32_t, 3>* const triangles_;
  uint32_t* const materials_;
  size_t vertexCount_ = 0;
  ObjChunkResult out_;
  ObjData& data_ = out_.data;
  std::vector<uint32_t> polygon_;                          // the corners of the face being read
  std::vector<uint32_t> polygonTex_;                       // the corners' texture coordinate indices
  std::unordered_map<std::string, uint32_t> materialIds_;  // this chunk's names
  uint32_t& currentMaterial_ = out_.materialAtEnd;
};

}  // namespace

ObjData parseObj(std::string_view text, const std::string& path, size_t chunkBytes, ImportProgress* progress) {
  const std::vector<ObjChunk> chunks = cutObjText(text, std::max<size_t>(chunkBytes, 1), progress);
  ObjData file;
  if (!chunks.empty()) {
    const size_t vertices = chunks.back().verticesBefore + chunks.back().vertices;
    const size_t triangles = chunks.back().trianglesBefore + chunks.back().triangles;
    // Counted before a word is checked: a text of bare `v` lines asks for 12 times its size before its first line
    // fails, so the sizes are checked against the memory there is first.
    checkMemory(double(vertices) * sizeof(Vec3) + double(triangles) * (sizeof(file.triangles[0]) + sizeof(uint32_t)),
                path,
                "reading " + std::to_string(vertices) + " vertices and " + std::to_string(triangles) + " triangles");
    if (progress) {
      progress->resize(file.vertices, vertices, 0.2);
      progress->resize(file.triangles, triangles, 0.2);
      progress->resize(file.triangleMaterial, triangles, 0.2);
    } else {
      file.vertices.resize(vertices);
      file.triangles.resize(triangles);
      file.triangleMaterial.resize(triangles);
    }
  }
  std::vector<ObjChunkResult> parts(chunks.size());
  std::vector<std::exception_ptr> errors(chunks.size());
  std::atomic<size_t> firstError{chunks.size()};  // chunks after a failed one need not be read
  std::atomic<size_t> read{0};
  tbb::parallel_for(
      size_t(0), chunks.size(),
      [&](size_t k) {
        if (k > firstError.load() || (progress && progress->cancelled())) return;
        // A chunk a step: 2.5 ms of reading (kObjChunkBytes at 200 MB/s).
        if (progress) progress->report(0.2 + 0.7 * double(read++) / double(chunks.size()));
        try {
          parts[k] = ObjParser(chunks[k], path, file).run();
        } catch (...) {
          errors[k] = std::current_exception();
          size_t seen = firstError.load();
          while (k < seen && !firstError.compare_exchange_weak(seen, k)) {
          }
        }
      },
      tbb::simple_partitioner());
  if (progress) progress->check();  // chunks were left unread: their errors are not the file's first
  // The first error of the file, as one-piece reading would meet it.
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  joinObjChunks(parts, path, file);
  return file;
}

}  // namespace vox
