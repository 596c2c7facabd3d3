// The PLY header (ply_header.h): one line at a time, every word checked.
#include "import/ply_header.h"

#include <algorithm>
#include <charconv>
#include <sstream>

#include "vox/core/error.h"
#include "import/obj_reader.h"

namespace vox {
namespace {

// Reads one header line's property into `e`; false when malformed.
bool parseProperty(const std::vector<std::string>& w, PlyElement& e) {
  PlyProperty p;
  if (w.size() == 5 && w[1] == "list") {
    const auto count = plyType(w[2]);
    const auto value = plyType(w[3]);
    if (!count || !value || isPlyFloat(*count)) return false;
    p = {w[4], true, *count, *value, PlyRole::Skip};
  } else if (w.size() == 3) {
    const auto value = plyType(w[1]);
    if (!value) return false;
    p = {w[2], false, PlyType::UInt8, *value, PlyRole::Skip};
  } else {
    return false;
  }
  e.properties.push_back(p);
  return true;
}

}  // namespace

std::optional<PlyType> plyType(std::string_view t) {
  if (t == "char" || t == "int8") return PlyType::Int8;
  if (t == "uchar" || t == "uint8") return PlyType::UInt8;
  if (t == "short" || t == "int16") return PlyType::Int16;
  if (t == "ushort" || t == "uint16") return PlyType::UInt16;
  if (t == "int" || t == "int32") return PlyType::Int32;
  if (t == "uint" || t == "uint32") return PlyType::UInt32;
  if (t == "float" || t == "float32") return PlyType::Float32;
  if (t == "double" || t == "float64") return PlyType::Float64;
  return std::nullopt;
}

const char* plyTypeName(PlyType t) {
  static const char* kNames[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double"};
  return kNames[static_cast<int>(t)];
}

size_t plyTypeSize(PlyType t) {
  static const size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(t)];
}

bool isPlyFloat(PlyType t) { return t == PlyType::Float32 || t == PlyType::Float64; }

bool isPlySigned(PlyType t) { return t == PlyType::Int8 || t == PlyType::Int16 || t == PlyType::Int32; }

void plyIntegerRange(PlyType t, long long& lo, long long& hi) {
  const int bits = 8 * static_cast<int>(plyTypeSize(t));
  lo = isPlySigned(t) ? -(1LL << (bits - 1)) : 0;
  hi = isPlySigned(t) ? (1LL << (bits - 1)) - 1 : (1LL << bits) - 1;
}

PlyHeader parseHeader(std::string_view data, const std::string& path) {
  PlyHeader h;
  size_t pos = 0;
  for (;;) {
    const size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) fail<InputError>(path, ": PLY header has no end_header line");
    std::string line(data.substr(pos, eol - pos));
    pos = eol + 1;
    const long long lineNumber = ++h.lines;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    auto bad = [&]() { fail<InputError>(path, ":", lineNumber, ": malformed PLY header line ", quotedWord(line)); };
    if (lineNumber == 1) {
      if (w.size() != 1 || w[0] != "ply") fail<InputError>(path, ": not a PLY file (first line is not 'ply')");
    } else if (lineNumber == 2) {
      if (w.size() != 3 || w[0] != "format" || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad();
      h.format = w[1];
    } else if (w.empty() || w[0] == "comment" || w[0] == "obj_info") {
      continue;
    } else if (w[0] == "end_header") {
      break;
    } else if (w[0] == "element") {
      if (w.size() != 3) bad();
      PlyElement e{w[1], -1, {}};
      const auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || end != w[2].data() + w[2].size() || e.count < 0) bad();
      h.elements.push_back(e);
    } else if (w[0] == "property") {
      if (h.elements.empty() || !parseProperty(w, h.elements.back())) bad();
    } else {
      bad();
    }
  }
  h.bodyStart = pos;
  return h;
}

void assignRoles(PlyHeader& h, const std::string& path) {
  bool haveVertex = false;
  for (PlyElement& e : h.elements) {
    if (e.name == "vertex") {
      if (haveVertex) fail<InputError>(path, ": PLY header has two vertex elements");
      haveVertex = true;
      int found = 0;
      for (PlyProperty& p : e.properties) {
        if (p.list || p.name.size() != 1 || p.name[0] < 'x' || p.name[0] > 'z') continue;
        p.role = p.name == "x" ? PlyRole::X : (p.name == "y" ? PlyRole::Y : PlyRole::Z);
        ++found;
      }
      if (found != 3) fail<InputError>(path, ": PLY vertex element needs exactly one each of x, y, z properties");
    } else if (e.name == "face") {
      for (PlyProperty& p : e.properties)
        if (p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
          if (isPlyFloat(p.valueType))
            fail<InputError>(path, ": PLY face property '", p.name, "' holds ", plyTypeName(p.valueType), " values");
          p.role = PlyRole::Indices;
        }
    }
  }
  if (!haveVertex) fail<InputError>(path, ": PLY header has no vertex element");
}

void checkCounts(const PlyHeader& h, size_t bodyBytes, const std::string& path) {
  const bool ascii = h.format == "ascii";
  // An ASCII value takes at least a character and a separator (the last one may lack its separator).
  unsigned long long budget = ascii ? bodyBytes + 1 : bodyBytes;
  for (const PlyElement& e : h.elements) {
    unsigned long long least = 0;  // bytes per element at least
    for (const PlyProperty& p : e.properties) least += ascii ? 2 : plyTypeSize(p.list ? p.countType : p.valueType);
    least = std::max(least, 1ULL);
    const auto count = static_cast<unsigned long long>(e.count);
    if (count > budget / least)
      fail<InputError>(path, ": PLY element ", quotedWord(e.name), " declares ", e.count, " items, more than the ",
                       bodyBytes, " bytes after the header can hold (truncated?)");
    budget -= count * least;
  }
}

}  // namespace vox
