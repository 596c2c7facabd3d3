// The OBJ / MTL reader (obj_reader.h). One pass over the text held in memory; every face is resolved and
// triangulated as it is read, so the cost is linear in the file size whatever the polygon sizes.
#include "import/obj_reader.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <utility>

#include "vox/core/error.h"
#include "vox/core/huge_pages.h"
#include "vox/io/input_file.h"

namespace vox {
namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Logical lines of a text: CR before LF dropped, a line ending in a backslash joined with the next one.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  // The next logical line and the number of its first physical line; false at the end of the text.
  bool next(std::string_view& line, long long& number) {
    if (pos_ >= text_.size()) return false;
    number = physical_ + 1;
    joined_.clear();
    bool joining = false;
    for (;;) {
      size_t eol = text_.find('\n', pos_);
      if (eol == std::string_view::npos) eol = text_.size();
      std::string_view piece = text_.substr(pos_, eol - pos_);
      pos_ = eol + 1;
      ++physical_;
      if (!piece.empty() && piece.back() == '\r') piece.remove_suffix(1);
      const bool continues = !piece.empty() && piece.back() == '\\';
      if (continues) piece.remove_suffix(1);
      if (!continues && !joining) {
        line = piece;
        return true;
      }
      joined_.append(piece);
      joined_ += ' ';
      joining = true;
      if (!continues || pos_ >= text_.size()) break;
    }
    line = joined_;
    return true;
  }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  long long physical_ = 0;
  std::string joined_;  // a line built from continuations
};

// Whitespace-separated words of one line; a word starting with '#' ends the line.
struct Words {
  std::string_view rest;

  std::string_view next() {
    size_t i = 0;
    while (i < rest.size() && isBlank(rest[i])) ++i;
    rest.remove_prefix(i);
    if (rest.empty() || rest[0] == '#') {
      rest = {};
      return {};
    }
    size_t j = 0;
    while (j < rest.size() && !isBlank(rest[j])) ++j;
    const std::string_view word = rest.substr(0, j);
    rest.remove_prefix(j);
    return word;
  }

  // The rest of the line without surrounding blanks (a name may hold spaces).
  std::string_view name() {
    while (!rest.empty() && isBlank(rest.front())) rest.remove_prefix(1);
    while (!rest.empty() && isBlank(rest.back())) rest.remove_suffix(1);
    return rest;
  }
};

// A whole word as a finite double, rounded to nearest by std::from_chars. A leading '+' is accepted as
// strtod does; "nan", "inf", hexadecimal and out-of-range numbers are refused.
bool parseNumber(std::string_view s, double& value) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty() || s[0] == '+') return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc() && end == s.data() + s.size() && std::isfinite(value);
}

enum class IntegerStatus { Ok, Bad, TooLarge };

IntegerStatus parseInteger(std::string_view s, long long& value) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty() || s[0] == '+') return IntegerStatus::Bad;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (end != s.data() + s.size()) return IntegerStatus::Bad;
  if (ec == std::errc::result_out_of_range) return IntegerStatus::TooLarge;
  return ec == std::errc() ? IntegerStatus::Ok : IntegerStatus::Bad;
}

class ObjParser {
 public:
  ObjParser(std::string_view text, const std::string& path) : lines_(text), path_(path) {}

  ObjData run() {
    std::string_view line;
    long long number = 0;
    while (lines_.next(line, number)) statement(Words{line}, number);
    checkForwardIndices();
    if (unknownCount_ > 0)
      data_.warnings.push_back(path_ + ": skipped " + std::to_string(unknownCount_) +
                               " statements with unknown keywords (first " + quotedWord(firstUnknown_) + " at line " +
                               std::to_string(firstUnknownLine_) + ")");
    return std::move(data_);
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
    } else if (unknownCount_++ == 0) {
      firstUnknown_ = std::string(keyword);
      firstUnknownLine_ = line;
    }
  }

  void vertex(Words& words, long long line) {
    double xyz[3];
    for (double& c : xyz) {
      const std::string_view w = words.next();
      if (w.empty()) failAt(line, "vertex needs 3 coordinates");
      if (!parseNumber(w, c)) failAt(line, "bad number ", quotedWord(w));
    }
    // A fourth number (w) or a colour (r g b) may follow: checked, not kept.
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      double ignored = 0;
      if (!parseNumber(w, ignored)) failAt(line, "bad number ", quotedWord(w));
    }
    growOnHugePages(data_.vertices);
    data_.vertices.push_back({xyz[0], xyz[1], xyz[2]});
  }

  // `vt u [v [w]]`: u and v kept exactly as written.
  void texcoord(Words& words, long long line) {
    double uvw[3] = {0, 0, 0};
    int n = 0;
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      if (n == 3) failAt(line, "vt takes at most 3 numbers");
      if (!parseNumber(w, uvw[n++])) failAt(line, "bad number ", quotedWord(w));
    }
    if (n == 0) failAt(line, "vt needs a number");
    data_.texcoords.push_back({uvw[0], uvw[1]});
  }

  // The 0-based texture coordinate index written `t` in a face corner, or kNoObjTexcoord when empty.
  uint32_t texcoordIndex(std::string_view t, std::string_view word, long long line) {
    if (t.empty()) return kNoObjTexcoord;
    long long i = 0;
    const IntegerStatus status = parseInteger(t, i);
    if (status == IntegerStatus::Bad) failAt(line, "bad face index ", quotedWord(word));
    const long long seen = static_cast<long long>(data_.texcoords.size());
    const long long zeroBased = i > 0 ? i - 1 : seen + i;
    // Judged at the end: a file without any `vt` has its texture indices ignored, as they always were.
    if (status == IntegerStatus::TooLarge || i == 0 || zeroBased < 0 ||
        zeroBased >= static_cast<long long>(UINT32_MAX)) {
      forwardTex_.push_back({kNoObjTexcoord, line, i});
      return 0;
    }
    if (zeroBased >= seen) forwardTex_.push_back({static_cast<uint32_t>(zeroBased), line, i});
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
        if (!index.empty() && parseInteger(index, ignored) == IntegerStatus::Bad)
          failAt(line, "bad face index ", quotedWord(word));
        if (part == 0) tex = texcoordIndex(index, word, line);
        if (next == std::string_view::npos) break;
        if (part == 1) failAt(line, "bad face index ", quotedWord(word));
        tail = tail.substr(next + 1);
      }
    }
    long long i = 0;
    const IntegerStatus status = parseInteger(head, i);
    const long long seen = static_cast<long long>(data_.vertices.size());
    if (status == IntegerStatus::Bad) failAt(line, "bad face index ", quotedWord(word));
    if (status == IntegerStatus::TooLarge)
      failAt(line, "face index ", quotedWord(head), " out of range (", seen, " vertices)");
    const long long zeroBased = i > 0 ? i - 1 : seen + i;
    // No file within kMaxObjFileBytes holds 2^32 - 1 vertices, so such an index can never be valid.
    if (i == 0 || zeroBased < 0 || zeroBased >= static_cast<long long>(UINT32_MAX))
      failAt(line, "face index ", i, " out of range (", seen, " vertices)");
    if (zeroBased >= seen) forward_.push_back({static_cast<uint32_t>(zeroBased), line, i});
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
    for (size_t k = 1; k + 1 < polygon_.size(); ++k) {
      growOnHugePages(data_.triangles);
      growOnHugePages(data_.triangleMaterial);
      data_.triangles.push_back({polygon_[0], polygon_[k], polygon_[k + 1]});
      data_.triangleMaterial.push_back(currentMaterial_);
      if (textured) {
        // Texture coordinates appear with the first face that has them; earlier faces get none.
        data_.triangleTexcoords.resize(data_.triangles.size() - 1, {kNoObjTexcoord, kNoObjTexcoord, kNoObjTexcoord});
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

  // Positive indices may name vertices defined further down; they are checked once all vertices are known.
  void checkForwardIndices() {
    const size_t count = data_.vertices.size();
    for (const ForwardIndex& f : forward_)
      if (f.zeroBased >= count) failAt(f.line, "face index ", f.written, " out of range (", count, " vertices)");
    if (data_.texcoords.empty()) data_.triangleTexcoords.clear();
    for (const ForwardIndex& f : forwardTex_)
      if (!data_.texcoords.empty() && f.zeroBased >= data_.texcoords.size())
        failAt(f.line, "texture coordinate index ", f.written, " out of range (", data_.texcoords.size(),
               " texture coordinates)");
  }

  struct ForwardIndex {
    uint32_t zeroBased;
    long long line;
    long long written;
  };

  LineReader lines_;
  const std::string& path_;
  ObjData data_;
  std::vector<uint32_t> polygon_;  // the corners of the face being read
  std::vector<ForwardIndex> forward_;
  std::vector<uint32_t> polygonTex_;  // the corners' texture coordinate indices
  std::vector<ForwardIndex> forwardTex_;
  std::unordered_map<std::string, uint32_t> materialIds_;
  uint32_t currentMaterial_ = kNoObjMaterial;
  size_t unknownCount_ = 0;
  std::string firstUnknown_;
  long long firstUnknownLine_ = 0;
};

// `Kd`/`Ks`: one number (grey) or three; each finite and not negative.
Vec3 readColour(Words& words, std::string_view keyword, const std::string& path, long long line) {
  double c[3];
  int n = 0;
  for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
    double v = 0;
    if (!parseNumber(w, v)) fail<InputError>(path, ":", line, ": bad number ", quotedWord(w), " in ", keyword);
    if (v < 0) fail<InputError>(path, ":", line, ": ", keyword, " value ", v, " is negative");
    if (n == 3) fail<InputError>(path, ":", line, ": ", keyword, " needs 1 or 3 numbers");
    c[n++] = v;
  }
  if (n == 1) return {c[0], c[0], c[0]};
  if (n != 3) fail<InputError>(path, ":", line, ": ", keyword, " needs 1 or 3 numbers");
  return {c[0], c[1], c[2]};
}

double readScalar(Words& words, std::string_view keyword, const std::string& path, long long line) {
  const std::string_view w = words.next();
  double v = 0;
  if (w.empty()) fail<InputError>(path, ":", line, ": ", keyword, " needs a number");
  if (!parseNumber(w, v)) fail<InputError>(path, ":", line, ": bad number ", quotedWord(w), " in ", keyword);
  return v;
}

}  // namespace

std::string quotedWord(std::string_view word) {
  std::string out(1, '\'');
  out += quoteInput(std::string(word));
  out += '\'';
  return out;
}

std::string readTextFile(const std::string& path, const char* what, size_t maxBytes) {
  requireRegularFile(path, what);
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  auto tooLarge = [&](uintmax_t bytes) {
    fail<InputError>(path, ": ", what, " is ", bytes, " bytes, more than the limit of ", maxBytes, " bytes");
  };
  if (!ec && size > maxBytes) tooLarge(size);
  std::string text = readInputFile(path, what);  // regular files only, within the memory budget
  if (text.size() > maxBytes) tooLarge(text.size());
  return text;
}

ObjData parseObj(std::string_view text, const std::string& path) { return ObjParser(text, path).run(); }

// `map_Kd [options] FILE`: the options of the MTL specification skipped with their arguments.
MtlDiffuseMap readDiffuseMap(Words& words, const std::string& path, long long line,
                             std::vector<std::string>& warnings) {
  MtlDiffuseMap map;
  map.line = line;
  auto where = [&] { return path + ":" + std::to_string(line) + ": map_Kd"; };
  while (true) {
    Words peek = words;
    const std::string_view option = peek.next();
    if (option.size() < 2 || option[0] != '-') break;
    words = peek;
    int args = 1;
    if (option == "-mm") args = 2;
    if (option == "-o" || option == "-s" || option == "-t") {
      // One to three numbers; anything but the default (0 offset, 1 scale, 0 turbulence) changes the mapping.
      const double neutral = option == "-s" ? 1 : 0;
      bool ignored = false;
      for (int k = 0; k < 3; ++k) {
        Words again = words;
        const std::string_view w = again.next();
        double v = 0;
        if (w.empty() || !parseNumber(w, v)) break;
        words = again;
        ignored |= v != neutral;
      }
      if (ignored) warnings.push_back(where() + " option " + std::string(option) + " is ignored");
      continue;
    }
    const bool known = option == "-blendu" || option == "-blendv" || option == "-cc" || option == "-clamp" ||
                       option == "-bm" || option == "-boost" || option == "-texres" || option == "-imfchan" ||
                       option == "-mm" || option == "-type";
    if (!known) {
      warnings.push_back(where() + " unknown option " + quotedWord(option) + " skipped");
      continue;
    }
    for (int k = 0; k < args; ++k) {
      const std::string_view value = words.next();
      if (value.empty()) fail<InputError>(where(), " option ", std::string(option), " needs a value");
      if (option == "-clamp") map.clamp = value == "on";
    }
  }
  map.file = std::string(words.name());
  if (map.file.empty()) fail<InputError>(where(), " needs a file name");
  return map;
}

std::vector<Material> parseMtl(std::string_view text, const std::string& path, std::vector<std::string>& warnings,
                               std::vector<MtlDiffuseMap>* maps) {
  std::vector<Material> out;
  std::vector<bool> kdGiven;
  const size_t firstMap = maps ? maps->size() : 0;
  LineReader lines(text);
  std::string_view line;
  long long number = 0;
  Material unnamed;  // takes values given before any newmtl, which no face can use
  while (lines.next(line, number)) {
    Words words{line};
    const std::string_view keyword = words.next();
    Material& m = out.empty() ? unnamed : out.back();
    if (keyword == "newmtl") {
      const std::string_view name = words.name();
      if (name.empty()) fail<InputError>(path, ":", number, ": newmtl needs a name");
      Material fresh;
      fresh.name = std::string(name);
      fresh.diffuse = {0, 0, 0};
      out.push_back(fresh);
      kdGiven.push_back(false);
    } else if (keyword == "Kd") {
      m.diffuse = readColour(words, keyword, path, number);
      if (!out.empty()) kdGiven.back() = true;
    } else if (keyword == "map_Kd") {
      MtlDiffuseMap map = readDiffuseMap(words, path, number, warnings);
      if (maps && !out.empty()) {
        map.material = out.size() - 1;
        maps->push_back(std::move(map));
      }
    } else if (keyword == "Ks") {
      m.specular = readColour(words, keyword, path, number);
    } else if (keyword == "Ns") {
      m.exponent = readScalar(words, keyword, path, number);
      if (m.exponent < 0) fail<InputError>(path, ":", number, ": Ns ", m.exponent, " is negative");
    } else if (keyword == "Ni") {
      const double ior = readScalar(words, keyword, path, number);
      if (ior < 0) fail<InputError>(path, ":", number, ": Ni ", ior, " is negative");
      if (ior == 0)
        warnings.push_back(path + ":" + std::to_string(number) + ": Ni 0 is no index of refraction; 1 is used");
      else
        m.indexOfRefraction = ior;
    }
    // Ka, Ke, d, Tr, illum and other texture maps carry nothing the tools use.
  }
  if (maps)
    for (size_t k = firstMap; k < maps->size(); ++k)
      if (!kdGiven[(*maps)[k].material]) out[(*maps)[k].material].diffuse = {1, 1, 1};
  return out;
}

}  // namespace vox
