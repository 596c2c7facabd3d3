// The MTL reader (obj_reader.h: parseMtl): the materials of an OBJ file's libraries and their diffuse maps.
#include <string>
#include <string_view>
#include <vector>

#include "import/obj_reader.h"
#include "import/obj_text.h"
#include "vox/core/error.h"

namespace vox {
namespace {

// `Kd`/`Ks`: one number (grey) or three; each finite and not negative.
Vec3 readColour(Words& words, std::string_view keyword, const std::string& path, long long line) {
  double c[3];
  int n = 0;
  for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
    double v = 0;
    if (!parseObjNumber(w, v)) fail<InputError>(path, ":", line, ": bad number ", quotedWord(w), " in ", keyword);
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
  if (!parseObjNumber(w, v)) fail<InputError>(path, ":", line, ": bad number ", quotedWord(w), " in ", keyword);
  return v;
}

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
        if (w.empty() || !parseObjNumber(w, v)) break;
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

}  // namespace

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
