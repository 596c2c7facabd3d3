// libFuzzer target: OBJ files through vox::loadScene (fuzz/fuzz_entry.h), and the same bytes read by parseObj in one
// piece and in chunks of 1-64 bytes (obj_chunks.h), which must agree in every field and in the first error.
#include <bit>
#include <cstdlib>
#include <string>

#include "fuzz_entry.h"
#include "import/obj_reader.h"

namespace {

// Every field of a reading (or its error) as text, numbers by their bits.
std::string describe(std::string_view text, size_t chunkBytes) {
  std::string out;
  try {
    const vox::ObjData d = vox::parseObj(text, "a.obj", chunkBytes);
    auto add = [&](auto value) { out += std::to_string(value) + ' '; };
    for (const vox::Vec3& v : d.vertices)
      for (int k = 0; k < 3; ++k) add(std::bit_cast<uint64_t>(v[k]));
    out += "|";
    for (const auto& t : d.triangles) add(t[0]), add(t[1]), add(t[2]);
    for (uint32_t m : d.triangleMaterial) add(m);
    for (size_t i = 0; i < d.materialNames.size(); ++i) out += d.materialNames[i] + ' ', add(d.materialLines[i]);
    for (const vox::ObjLibrary& l : d.libraries) out += l.name + ' ', add(l.line);
    for (const vox::TexCoord& t : d.texcoords) add(std::bit_cast<uint64_t>(t.u)), add(std::bit_cast<uint64_t>(t.v));
    for (const auto& t : d.triangleTexcoords) add(t[0]), add(t[1]), add(t[2]);
    for (const std::string& w : d.warnings) out += w;
  } catch (const vox::InputError& e) {
    out = std::string("error: ") + e.what();
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  vox::fuzz::loadSceneBytes(text, "obj");
  const size_t chunkBytes = 1 + (size > 0 ? data[0] % 64 : 0);
  if (describe(text, size_t{1} << 40) != describe(text, chunkBytes)) std::abort();
  return 0;
}
