// The header of a PLY file (Turk's format 1.0): its format, elements and properties, which of them the mesh reader
// uses (x, y, z of `vertex`, the index list of `face`), and the element counts checked against the bytes of the body
// before the body is read (import_ply.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vox {

enum class PlyType : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<PlyType> plyType(std::string_view t);
const char* plyTypeName(PlyType t);
size_t plyTypeSize(PlyType t);
bool isPlyFloat(PlyType t);
bool isPlySigned(PlyType t);
// The range of an integer type.
void plyIntegerRange(PlyType t, long long& lo, long long& hi);

// What a property means to us.
enum class PlyRole : uint8_t { Skip, X, Y, Z, Indices };

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType countType = PlyType::UInt8;  // list only
  PlyType valueType = PlyType::Float32;
  PlyRole role = PlyRole::Skip;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::string format;
  std::vector<PlyElement> elements;
  size_t bodyStart = 0;  // byte offset of the first byte after end_header's line
  long long lines = 0;   // header lines, so that the body's first line is lines + 1
};

// The header at the start of `data`; InputError naming `path` and the line when it is not a PLY 1.0 header.
PlyHeader parseHeader(std::string_view data, const std::string& path);
// Marks the properties we read (x, y, z of `vertex`, the index list of `face`) and checks they are usable.
void assignRoles(PlyHeader& h, const std::string& path);
// Refuses any element count the body cannot hold, before anything is allocated or walked.
void checkCounts(const PlyHeader& h, size_t bodyBytes, const std::string& path);

}  // namespace vox
