// PLY triangle meshes (Turk's format: ascii, binary_little_endian, binary_big_endian 1.0), read here in one pass
// over the file held in memory.
// Why not OpenMesh's reader (9.0): it reads every point into a Vec3f, so a `double` property loses its low bits
// (ASCII and binary alike), and it trusts its input (it loops forever on a header without `end_header`, grows a
// vector until memory runs out on a corrupt list count, drops faces with an invalid index with a message on
// std::cerr). Here:
// - every value is checked against its declared type: an ASCII value that does not fit (`1e39` in a float, `300` in
//   a uchar, `-1` in a uint) or is not a finite number is an InputError naming the line; binary coordinates must be
//   finite;
// - coordinates are kept as the file gives them: a `double` property bit for bit, a `float` one exactly as its
//   float value, an ASCII number rounded once to the nearest double (DESIGN.md);
// - each element count is checked against the bytes that remain before anything is allocated or walked: an ASCII
//   value takes at least 2 bytes (digit and separator), a binary one its size; an element with no properties is
//   allowed at most one per remaining byte (it holds no data; this bound only stops absurd counts);
// - faces: the `vertex_indices` (or `vertex_index`) list, fan-triangulated; an index outside the vertices is an
//   error; repeated indices give degenerate triangles, kept as DESIGN.md says; faces with fewer than 3 vertices
//   are skipped with one warning. Other elements and properties are checked and skipped.
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "import/import_progress.h"
#include "import/obj_reader.h"
#include "import/ply_header.h"
#include "vox/core/error.h"
#include "vox/core/huge_pages.h"
#include "vox/import/import.h"

namespace vox {
namespace {

// Larger files are refused before they are read.
constexpr size_t kMaxPlyFileBytes = size_t{8} << 30;

struct PlyMesh {
  HugeVector<Vec3> vertices;
  HugeVector<std::array<uint32_t, 3>> triangles;
  long long shortFaces = 0;  // faces with fewer than 3 vertices, skipped
};

// ASCII body: whitespace-separated tokens, each checked against its declared type.
class AsciiCursor {
 public:
  AsciiCursor(std::string_view data, const PlyHeader& h, const std::string& path)
      : data_(data), pos_(h.bodyStart), line_(h.lines + 1), path_(path) {}
  // Over one line of the body (line number `line` of the file): the element of that line, read by itself.
  AsciiCursor(std::string_view line, long long number, const std::string& path)
      : data_(line), pos_(0), line_(number), path_(path) {}

  // Whether nothing but white space is left.
  bool atEnd() {
    while (pos_ < data_.size() && isSpace(data_[pos_])) ++pos_;
    return pos_ == data_.size();
  }

  void at(const PlyElement& e, long long i) {
    element_ = &e;
    index_ = i;
  }
  size_t remaining() const { return data_.size() - pos_; }
  // The largest list length the rest of the file can hold: a separator and a character per value, whatever its type.
  unsigned long long maxListLength(size_t /*valueBytes*/) const { return (remaining() + 1) / 2; }

  double real(PlyType t) {
    const std::string_view token = next();
    if (!isPlyFloat(t)) return static_cast<double>(integer(t, token));
    std::string_view s = token;
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || s[0] == '+' || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
      failHere("bad number ", quotedWord(token));
    if (t == PlyType::Float32 && std::fabs(v) > FLT_MAX) failHere("value ", token, " does not fit in a float property");
    return v;
  }

  // `t` is an integer type (list counts and indices: parseHeader and assignRoles see to it).
  long long integer(PlyType t) { return integer(t, next()); }

  template <typename... Parts>
  [[noreturn]] void failHere(const Parts&... parts) const {
    fail<InputError>(path_, ":", tokenLine_, ": ", element_->name, " ", index_, ": ", parts...);
  }

 private:
  // The C locale's white space, spelled out: std::isspace is a library call per byte (13% of a PLY's reading) and
  // follows a locale a program may have changed.
  static bool isSpace(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

  std::string_view next() {
    while (pos_ < data_.size() && isSpace(data_[pos_])) {
      if (data_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= data_.size())
      fail<InputError>(path_, ": PLY file ends inside ", element_->name, " ", index_, " (truncated?)");
    const size_t start = pos_;
    while (pos_ < data_.size() && !isSpace(data_[pos_])) ++pos_;
    tokenLine_ = line_;
    return data_.substr(start, pos_ - start);
  }

  long long integer(PlyType t, std::string_view token) const {
    std::string_view s = token;
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    long long v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    const bool tooLarge = ec == std::errc::result_out_of_range;
    if (s.empty() || s[0] == '+' || end != s.data() + s.size() || (ec != std::errc() && !tooLarge))
      failHere("bad ", plyTypeName(t), " value ", quotedWord(token));
    long long lo = 0, hi = 0;
    plyIntegerRange(t, lo, hi);
    if (tooLarge || v < lo || v > hi) failHere("value ", token, " does not fit in a ", plyTypeName(t), " property");
    return v;
  }

  std::string_view data_;
  size_t pos_;
  long long line_;
  long long tokenLine_ = 0;
  const std::string& path_;
  const PlyElement* element_ = nullptr;
  long long index_ = 0;
};

// Binary body: values in the file's byte order; bounds are checked before every read.
class BinaryCursor {
 public:
  BinaryCursor(std::string_view data, const PlyHeader& h, const std::string& path)
      : bytes_(reinterpret_cast<const unsigned char*>(data.data())),
        size_(data.size()),
        pos_(h.bodyStart),
        bigEndian_(h.format == "binary_big_endian"),
        path_(path) {}

  void at(const PlyElement& e, long long i) {
    element_ = &e;
    index_ = i;
    start_ = pos_;
  }
  size_t remaining() const { return size_ - pos_; }
  unsigned long long maxListLength(size_t valueBytes) const { return remaining() / valueBytes; }

  double real(PlyType t) {
    const uint64_t u = raw(t);
    if (t == PlyType::Float64) return std::bit_cast<double>(u);
    if (t == PlyType::Float32) return static_cast<double>(std::bit_cast<float>(static_cast<uint32_t>(u)));
    return static_cast<double>(toInteger(t, u));
  }
  long long integer(PlyType t) { return toInteger(t, raw(t)); }

  template <typename... Parts>
  [[noreturn]] void failHere(const Parts&... parts) const {
    fail<InputError>(path_, ": ", element_->name, " ", index_, " (at byte ", start_, "): ", parts...);
  }

 private:
  uint64_t raw(PlyType t) {
    const size_t n = plyTypeSize(t);
    if (size_ - pos_ < n)
      fail<InputError>(path_, ": PLY file ends inside ", element_->name, " ", index_, " (truncated?)");
    uint64_t u = 0;
    for (size_t i = 0; i < n; ++i) u |= static_cast<uint64_t>(bytes_[pos_ + (bigEndian_ ? n - 1 - i : i)]) << (8 * i);
    pos_ += n;
    return u;
  }
  static long long toInteger(PlyType t, uint64_t u) {
    const size_t n = plyTypeSize(t);
    if (isPlySigned(t) && ((u >> (8 * n - 1)) & 1)) return static_cast<long long>(u) - (1LL << (8 * n));
    return static_cast<long long>(u);
  }

  const unsigned char* bytes_;
  size_t size_;
  size_t pos_;
  bool bigEndian_;
  const std::string& path_;
  const PlyElement* element_ = nullptr;
  long long index_ = 0;
  size_t start_ = 0;
};

// Reads one face's index list into `polygon`.
template <typename Cursor>
void readFace(Cursor& in, const PlyProperty& p, long long n, size_t vertexCount, std::vector<uint32_t>& polygon) {
  for (long long k = 0; k < n; ++k) {
    const long long v = in.integer(p.valueType);
    if (v < 0 || static_cast<unsigned long long>(v) >= vertexCount)
      in.failHere("vertex index ", v, " out of range (", vertexCount, " vertices)");
    polygon.push_back(static_cast<uint32_t>(v));
  }
}

// Reads one instance of element `e` (the cursor placed at it): its coordinates into xyz, its index list (when it has
// one) into `polygon`, every other value checked and skipped.
template <typename Cursor>
void readInstance(Cursor& in, const PlyElement& e, size_t vertexCount, double xyz[3], std::vector<uint32_t>& polygon) {
  polygon.clear();
  for (const PlyProperty& p : e.properties) {
    if (!p.list) {
      const double v = in.real(p.valueType);
      if (p.role == PlyRole::Skip) continue;
      if (!std::isfinite(v)) in.failHere("coordinate ", p.name, " is NaN or infinite");
      xyz[static_cast<int>(p.role) - static_cast<int>(PlyRole::X)] = v;
      continue;
    }
    const long long n = in.integer(p.countType);
    const size_t valueBytes = plyTypeSize(p.valueType);
    if (n < 0 || static_cast<unsigned long long>(n) > in.maxListLength(valueBytes)) in.failHere("bad list length ", n);
    if (p.role == PlyRole::Indices) {
      readFace(in, p, n, vertexCount, polygon);
    } else {
      for (long long k = 0; k < n; ++k) in.real(p.valueType);
    }
  }
}

// Reports to `progress` over [from, from + span] of the read.
template <typename Cursor>
void readElement(Cursor& in, const PlyElement& e, size_t vertexCount, PlyMesh& out, ImportProgress& progress,
                 double from, double span) {
  if (e.properties.empty()) return;  // holds no data; its count was bounded by checkCounts
  std::vector<uint32_t> polygon;
  const bool isVertex = e.name == "vertex";
  for (long long i = 0; i < e.count; ++i) {
    progress.step(uint64_t(i), from + span * double(i) / double(e.count));
    in.at(e, i);
    double xyz[3] = {0, 0, 0};
    readInstance(in, e, vertexCount, xyz, polygon);
    if (isVertex) out.vertices.push_back({xyz[0], xyz[1], xyz[2]});
    if (polygon.empty()) continue;
    if (polygon.size() < 3) {
      ++out.shortFaces;
      continue;
    }
    for (size_t k = 1; k + 1 < polygon.size(); ++k) out.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
  }
}

// Reports to `progress` from 0.1 to 0.9 of the read, each element its share of the instances.
template <typename Cursor>
PlyMesh readBody(Cursor in, const PlyHeader& h, ImportProgress& progress) {
  PlyMesh out;
  size_t vertexCount = 0;
  for (const PlyElement& e : h.elements) {
    if (e.name == "vertex") vertexCount = static_cast<size_t>(e.count);
    if (e.name == "face") out.triangles.reserve(static_cast<size_t>(e.count));
  }
  out.vertices.reserve(vertexCount);
  double instances = 0, before = 0;
  for (const PlyElement& e : h.elements) instances += double(e.count);
  for (const PlyElement& e : h.elements) {
    readElement(in, e, vertexCount, out, progress, 0.1 + 0.8 * before / std::max(instances, 1.0),
                0.8 * double(e.count) / std::max(instances, 1.0));
    before += double(e.count);
  }
  return out;
}

// ASCII bodies of 1 MiB and more, read on all threads: every writer we know puts one element on a line, so line k
// of the body is a known instance of a known element, and chunks of lines can be read side by side, each writing its
// vertices and triangles in place. This is tried only when it cannot change the result: every line must hold exactly
// its element, every face exactly 3 indices, and the lines after the last element nothing. Anything else (an error,
// a polygon, an element over two lines) returns nullopt, and the file is read again on one thread, which reports
// the file's first error as always.
// Reports to `progress` from 0.1 to 0.9 of the read.
std::optional<PlyMesh> readAsciiLines(std::string_view data, const PlyHeader& h, const std::string& path,
                                      ImportProgress& progress) {
  constexpr size_t kChunkBytes = size_t{1} << 19;
  const std::string_view body = data.substr(h.bodyStart);
  // On one thread the counting pass only adds time (10.8-11.1 ms against 9.1-9.7 for the bunny's PLY).
  const size_t threads = std::min(size_t(tbb::this_task_arena::max_concurrency()),
                                  tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (body.size() < 2 * kChunkBytes || threads < 2) return std::nullopt;
  // Each element with properties takes count lines, in header order; lineEnd[e] is the body line after element e.
  std::vector<long long> lineEnd;
  long long lines = 0;
  size_t vertexCount = 0, faceCount = 0;
  int vertexElements = 0, faceElements = 0;
  for (const PlyElement& e : h.elements) {
    if (!e.properties.empty()) lines += e.count;
    lineEnd.push_back(lines);
    if (e.name == "vertex") vertexCount = size_t(e.count), ++vertexElements;
    if (e.name == "face") faceCount = size_t(e.count), ++faceElements;
  }
  if (vertexElements > 1 || faceElements > 1) return std::nullopt;  // read one after the other, appended
  std::vector<std::string_view> chunks;
  for (size_t begin = 0; begin < body.size();) {
    size_t end = body.size();
    if (body.size() - begin >= 2 * kChunkBytes) {
      const size_t eol = body.find('\n', begin + kChunkBytes - 1);
      if (eol != std::string_view::npos) end = eol + 1;
    }
    chunks.push_back(body.substr(begin, end - begin));
    begin = end;
  }
  std::vector<long long> linesBefore(chunks.size() + 1, 0);
  std::atomic<size_t> counted{0};
  tbb::parallel_for(size_t(0), chunks.size(), [&](size_t k) {
    if (progress.cancelled()) return;
    linesBefore[k + 1] = std::count(chunks[k].begin(), chunks[k].end(), '\n');
    progress.report(0.1 + 0.05 * double(++counted) / double(chunks.size()));
  });
  progress.check();
  for (size_t k = 0; k < chunks.size(); ++k) linesBefore[k + 1] += linesBefore[k];
  if (linesBefore.back() + (body.back() != '\n') < lines) return std::nullopt;  // too few lines: not one a line

  PlyMesh out;
  out.vertices.resize(vertexCount);
  out.triangles.resize(faceCount);
  std::atomic<bool> fits{true};
  std::atomic<size_t> read{0};
  tbb::parallel_for(size_t(0), chunks.size(), [&](size_t k) {
    if (progress.cancelled()) return;
    progress.report(0.15 + 0.75 * double(read++) / double(chunks.size()));
    try {
      std::vector<uint32_t> polygon;
      long long line = linesBefore[k];
      size_t e = 0;
      for (std::string_view rest = chunks[k]; !rest.empty() && fits.load(std::memory_order_relaxed); ++line) {
        const size_t eol = rest.find('\n');
        const std::string_view text = rest.substr(0, eol);
        rest.remove_prefix(eol == std::string_view::npos ? rest.size() : eol + 1);
        while (e < lineEnd.size() && lineEnd[e] <= line) ++e;
        AsciiCursor in(text, h.lines + 1 + line, path);
        if (e == lineEnd.size()) {  // past the last element: only white space may follow
          if (!in.atEnd()) fits = false;
          continue;
        }
        const PlyElement& element = h.elements[e];
        const long long i = line - (e > 0 ? lineEnd[e - 1] : 0);
        in.at(element, i);
        double xyz[3] = {0, 0, 0};
        readInstance(in, element, vertexCount, xyz, polygon);
        if (!in.atEnd()) fits = false;
        if (element.name == "vertex") out.vertices[size_t(i)] = {xyz[0], xyz[1], xyz[2]};
        if (element.name == "face" && polygon.size() == 3)
          out.triangles[size_t(i)] = {polygon[0], polygon[1], polygon[2]};
        else if (element.name == "face" || !polygon.empty())
          fits = false;
      }
    } catch (const InputError&) {
      fits = false;
    }
  });
  progress.check();
  if (!fits) return std::nullopt;
  return out;
}

}  // namespace

Scene importPly(const std::string& path, const std::function<bool(double)>& progress) {
  ImportProgress report(progress, path);
  const HugeBuffer bytes = readTextFile(path, "PLY file", kMaxPlyFileBytes, &report);
  const std::string_view data = bytes.view();
  PlyHeader header = parseHeader(data, path);
  checkCounts(header, data.size() - header.bodyStart, path);
  assignRoles(header, path);
  std::optional<PlyMesh> lines;
  if (header.format == "ascii") lines = readAsciiLines(data, header, path, report);
  const PlyMesh mesh = lines                      ? std::move(*lines)
                       : header.format == "ascii" ? readBody(AsciiCursor(data, header, path), header, report)
                                                  : readBody(BinaryCursor(data, header, path), header, report);

  Scene scene;
  scene.materials.push_back(Material{"default"});
  scene.triangles.reserve(mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    report.step(i, 0.9 + 0.1 * double(i) / double(mesh.triangles.size()));
    const auto& f = mesh.triangles[i];
    scene.triangles.push_back({{mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]}, 0});
  }
  if (mesh.shortFaces > 0)
    scene.warnings.push_back(path + ": " + std::to_string(mesh.shortFaces) +
                             " faces with fewer than 3 vertices skipped");
  return scene;
}

}  // namespace vox
