// What every fuzz target runs, shared with tests/fuzz_regression_test.cpp so that a saved finding replays through
// exactly the code that found it. An input may be refused with vox::Error; any other exception, a signal, a
// sanitizer report or a hang is a finding.
#pragma once

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/io/info.h"
#include "vox/io/input_file.h"
#include "vox/import/import.h"
#include "vox/trace/render.h"
#include "vox/export/voxel_format.h"
#include "vox/export/voxel_mesh.h"

namespace vox::fuzz {

// A folder of this process's own under $TMPDIR (so parallel fuzzers never share an input file), removed at exit.
// Leaked on purpose: it must outlive the static destructors that run before the atexit handler.
inline const std::string& privateFolder() {
  static const std::string* folder = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "vox-fuzz-XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    auto* made = new std::string(pattern);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(privateFolder(), ignored);
    });
    return made;
  }();
  return *folder;
}

// Writes `bytes` to input.EXTENSION in the private folder and loads it through loadScene, as vox-voxelize does:
// the importers take a path, and the extension picks the importer (txt, obj, ply, gltf, glb).
inline void loadSceneBytes(std::string_view bytes, const std::string& extension) {
  const std::string path = privateFolder() + "/input." + extension;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) std::abort();
  }
  try {
    loadScene(path);
  } catch (const Error&) {
  }
}

// What a decoded grid file must survive: tracing in three modes and meshing. vox::Error is an acceptable answer,
// a crash is not. Shared by the fuzz target and tests/grid_file_test.cpp's structure fuzzing.
inline void exerciseDecodedGrid(const GridFile& file) {
  try {
    const Accel accel = buildAccel(file.scene, file.grid, AccelKind::Grid);
    RenderOptions options;
    // A walk is bounded by the sum of the grid's dims, and a valid but degenerate grid reaches that bound on every
    // ray (674627x2x1 cells, 1.8e88 deep: every cell within the walk's tolerance of its neighbours; 0.25 s for 36
    // rays in release, a hundred times that under coverage and ASan, tests/data/fuzz/grid/timeout-27cc5893-*). Such
    // long walks get one ray per image, so that the fuzzer's time goes to new inputs.
    const auto& d = file.grid.dims;
    options.width = options.height = uint64_t(d[0]) + d[1] + d[2] > 65536 ? 1 : 6;
    const auto bounds = sceneBounds(file.scene);
    options.camera = file.scene.camera ? *file.scene.camera : defaultCamera(bounds ? *bounds : file.grid.bounds);
    for (RenderMode mode : {RenderMode::Shade, RenderMode::Voxels, RenderMode::Depth}) {
      options.mode = mode;
      traceImage(file.scene, accel, options);
    }
    buildVoxelMesh(file.grid, file.scene, FaceMode::Exposed, ColorMode::Count);
    buildVoxelMesh(file.grid, file.scene, FaceMode::Merged, ColorMode::Material);
  } catch (const Error&) {
  }
}

// Rewrites the header's payload size (offset 16) and checksum (offset 24) of a grid file, manifest or brick file (all
// share the 32-byte header, docs/grid-format.md), so that mutations reach the readers' own checks of counts, offsets,
// ids and names instead of stopping at the checksum.
inline void fixHeader(std::string& bytes) {
  constexpr size_t kHeader = 32;
  if (bytes.size() < kHeader) return;
  const uint64_t size = bytes.size() - kHeader;
  const uint64_t sum = gridChecksum(bytes.data() + kHeader, size);
  std::memcpy(&bytes[16], &size, 8);
  std::memcpy(&bytes[24], &sum, 8);
}

// Decodes `bytes` as a grid file (header fixed first, fixHeader). What decodes is traced and exported
// (exerciseDecodedGrid).
inline void decodeGridBytes(std::string bytes) {
  fixHeader(bytes);
  GridFile file;
  try {
    file = decodeGridFile(bytes, "fuzz.vgrid");
  } catch (const Error&) {
    return;
  }
  exerciseDecodedGrid(file);
}

// A grid set as one input: the manifest, the scene file and the brick files (in the manifest's order), joined by
// this marker. scripts/fuzz.sh makes the seeds the same way.
inline constexpr std::string_view kSetPartMarker = "\nVOXPART\n";

inline std::vector<std::string> splitSetParts(std::string_view bytes) {
  std::vector<std::string> parts;
  for (size_t at = 0;;) {
    const size_t next = bytes.find(kSetPartMarker, at);
    parts.emplace_back(bytes.substr(at, next == std::string_view::npos ? std::string_view::npos : next - at));
    if (next == std::string_view::npos || parts.size() == 64) return parts;
    at = next + kSetPartMarker.size();
  }
}

// Where the harness writes a part the manifest names `name`, or nothing: relative, short, plain characters, and
// inside `area` (the set's folder or the folder above it, so that a name leading out of the set's folder finds a
// file there, which the reader must still refuse). Other names stay in the manifest for the reader to refuse.
inline std::optional<std::filesystem::path> partPath(const std::filesystem::path& area,
                                                     const std::filesystem::path& folder, const std::string& name) {
  if (name.empty() || name.size() > 96 || name.front() == '/' || name.back() == '/') return std::nullopt;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-' && c != '/')
      return std::nullopt;
  const std::string base = area.lexically_normal().string() + "/";
  const std::filesystem::path full = (folder / name).lexically_normal();
  if (full.string().compare(0, base.size(), base) != 0 ||
      std::distance(full.begin(), full.end()) > std::distance(area.begin(), area.end()) + 4)
    return std::nullopt;
  return full;
}

// Writes `bytes` at `path` (creating its folders); a failure only means no file.
inline void writePart(const std::filesystem::path& path, const std::string& bytes) {
  std::error_code ignored;
  std::filesystem::create_directories(path.parent_path(), ignored);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

// Whether `name` (relative to `folder`) stays inside `folder` lexically; nothing the harness writes is a link.
inline bool staysInside(const std::filesystem::path& folder, const std::string& name) {
  const std::filesystem::path p(name);
  if (p.is_absolute() || p.has_root_name()) return false;
  const std::string base = folder.lexically_normal().string();
  const std::string full = (folder / p).lexically_normal().string();
  return full.size() > base.size() && full.compare(0, base.size(), base) == 0 && full[base.size()] == '/';
}

// An error from reading a set must be one line that names a file of the set (its manifest, scene or brick file):
// the tools print it as it is (README "Limits and errors").
inline void checkSetError(const Error& e, const std::string& folder) {
  const std::string what = e.what();
  if (what.find('\n') != std::string::npos || what.find(folder) == std::string::npos) {
    std::fprintf(stderr, "set error without its file, or on more than one line: %s\n", what.c_str());
    std::abort();
  }
}

// binvox and .vox of a set that read whole as `file`: written from the assembled grid and lazily, layer by layer
// (writeGridSetVoxelFile, as vox-export does for a set). Either both writers refuse or both write the same bytes.
// Only for grids of up to 2^21 cells: binvox writes every cell of its cube.
inline void compareSetVoxelFiles(const GridFile& file, const std::string& setPath) {
  if (file.grid.cellCount() > (uint64_t(1) << 21)) return;
  const GridSetManifest m = readGridSetManifest(setPath);
  const GridFile sceneFile = readGridSetScene(setPath, m);
  for (const auto& [format, extension] :
       {std::pair{VoxelFormat::Binvox, ".binvox"}, {VoxelFormat::MagicaVoxel, ".vox"}}) {
    const std::string wholePath = privateFolder() + "/whole" + extension,
                      lazyPath = privateFolder() + "/lazy" + extension;
    std::string whole, lazy;
    bool wholeWritten = false, lazyWritten = false;
    try {
      writeVoxelFile(wholePath, format, file.grid, occupiedCellColors(file.grid, file.scene, ColorMode::Count));
      whole = readInputFile(wholePath, "voxel file"), wholeWritten = true;
    } catch (const Error&) {
    }
    try {
      writeGridSetVoxelFile(lazyPath, format, setPath, m, sceneFile, ColorMode::Count);
      lazy = readInputFile(lazyPath, "voxel file"), lazyWritten = true;
    } catch (const Error&) {
    }
    if (wholeWritten != lazyWritten || whole != lazy) {
      std::fprintf(stderr, "%s of the assembled set %s, of its layers %s, files %s\n", extension,
                   wholeWritten ? "written" : "refused", lazyWritten ? "written" : "refused",
                   whole == lazy ? "equal" : "differ");
      std::abort();
    }
  }
}

// A rerun over this set removes the files its manifest lists (removeGridSetFiles): a crafted manifest must never
// make it remove anything but files of the set layout inside the set's folder. Files the manifest may name, outside
// that layout or outside the folder, are planted first and must survive.
// fuzz.bricks/LEAF or fuzz.bricks/gHEX/LEAF, LEAF scene.vgrid or b_X_Y_Z.vgrid: the names removeGridSetFiles may
// remove for the manifest fuzz.vgrid, written out independently of it. (No std::regex: GCC 12 warns inside it at -O1.)
inline bool isFuzzSetLayoutName(std::string_view s) {
  const auto digits = [&](size_t max) {
    size_t n = 0;
    while (n < s.size() && n < max && std::isdigit(static_cast<unsigned char>(s[n]))) ++n;
    s.remove_prefix(n);
    return n > 0;
  };
  const auto text = [&](std::string_view t) {
    if (s.substr(0, t.size()) != t) return false;
    s.remove_prefix(t.size());
    return true;
  };
  if (!text("fuzz.bricks/")) return false;
  if (s.size() > 18 && s[0] == 'g' && s[17] == '/') {
    for (size_t i = 1; i < 17; ++i)
      if (!std::isdigit(static_cast<unsigned char>(s[i])) && !(s[i] >= 'a' && s[i] <= 'f')) return false;
    s.remove_prefix(18);
  }
  if (text("scene.vgrid")) return s.empty();
  return text("b_") && digits(10) && text("_") && digits(10) && text("_") && digits(10) && text(".vgrid") && s.empty();
}

inline void removeReplacedSet(const std::filesystem::path& area, const std::filesystem::path& folder,
                              const std::string& path, const GridSetManifest& m) {
  std::vector<std::filesystem::path> planted{area / "keep.vgrid", folder / "keep.vgrid"};
  std::vector<std::string> names{m.scene.file};
  for (const BrickEntry& e : m.entries) names.push_back(e.file);
  for (const std::string& name : names)
    if (const auto p = partPath(area, folder, name); p && !isFuzzSetLayoutName(name)) planted.push_back(*p);
  for (const auto& p : planted)
    if (!std::filesystem::exists(p)) writePart(p, "user data");
  removeGridSetFiles(path, m);
  for (const auto& p : planted)
    if (!std::filesystem::exists(p)) {
      std::fprintf(stderr, "removing a replaced set removed %s, not a file of its layout\n", p.c_str());
      std::abort();
    }
}

// Reads a grid set made of `bytes` (parts split by kSetPartMarker): headers fixed, then, when the manifest decodes,
// its listed sizes and checksums set to the parts given (so the bricks' contents are reached), each part written
// where the manifest names it inside the private folder, and the set read whole (readGridOrSet, as vox-trace and
// vox-export do: then traced, meshed and written as binvox and .vox, compared with the lazy writer) and lazily
// (writeGridSetInfo, as vox-info does). Findings besides crashes:
// a read that succeeds with a name leading out of the set's folder, an error that is not one line naming the set's
// file, and the two readers disagreeing (one refuses what the other reads, or their vox-info output differs).
inline void readGridSetBytes(std::string_view input) {
  std::vector<std::string> parts = splitSetParts(input);
  for (std::string& part : parts) fixHeader(part);
  GridSetManifest m;
  try {
    m = decodeGridSetManifest(parts[0], "fuzz.vgrid");
  } catch (const Error&) {
    return;
  }
  // The set's folder is set/m: names with ".." may land in set/, which is emptied with it before every input.
  const std::filesystem::path area = std::filesystem::path(privateFolder()) / "set", folder = area / "m";
  std::error_code ignored;
  std::filesystem::remove_all(area, ignored);
  std::filesystem::create_directories(folder, ignored);
  auto listPart = [&](size_t i, uint64_t& size, uint64_t& checksum) {
    if (i >= parts.size()) return;
    size = parts[i].size();
    checksum = 0;
    if (size >= 32) std::memcpy(&checksum, parts[i].data() + 24, 8);
  };
  auto placePart = [&](size_t i, const std::string& name) {
    if (i >= parts.size()) return;
    if (const auto path = partPath(area, folder, name)) writePart(*path, parts[i]);
  };
  listPart(1, m.scene.fileSize, m.scene.checksum);
  for (size_t i = 0; i < m.entries.size(); ++i) listPart(2 + i, m.entries[i].fileSize, m.entries[i].fileChecksum);
  placePart(1, m.scene.file);
  for (size_t i = 0; i < m.entries.size(); ++i) placePart(2 + i, m.entries[i].file);
  const std::string path = (folder / "fuzz.vgrid").string();
  writePart(path, encodeGridSetManifest(m));

  InfoOptions options;
  options.json = options.cells = true;
  std::string whole, lazy;
  bool wholeRead = false, lazyRead = false;
  try {
    const GridFile file = readGridOrSet(path);
    wholeRead = true;
    std::vector<std::string> names{m.scene.file};
    for (const BrickEntry& e : m.entries) names.push_back(e.file);
    for (const std::string& name : names)
      if (!staysInside(folder, name)) {
        std::fprintf(stderr, "a set was read through %s, outside its folder\n", quoteInput(name).c_str());
        std::abort();
      }
    whole = formatGridInfo(file, options);
    exerciseDecodedGrid(file);
    compareSetVoxelFiles(file, path);
  } catch (const Error& e) {
    checkSetError(e, folder.string());
  }
  try {
    std::ostringstream out;
    writeGridSetInfo(out, path, options);
    lazy = out.str();
    lazyRead = true;
  } catch (const Error& e) {
    checkSetError(e, folder.string());
  }
  if (wholeRead != lazyRead || whole != lazy) {
    std::fprintf(stderr, "readGridSet %s, the lazy reader %s, outputs %s\n", wholeRead ? "read" : "refused",
                 lazyRead ? "read" : "refused", whole == lazy ? "equal" : "differ");
    std::abort();
  }
  removeReplacedSet(area, folder, path, m);
}

// The grid target's input: a grid set (parts starting with the manifest's magic) or a grid file.
inline void readGridInput(std::string_view bytes) {
  if (bytes.size() >= 8 && bytes.substr(0, 8) == std::string_view("VOXGSET\n", 8))
    readGridSetBytes(bytes);
  else
    decodeGridBytes(std::string(bytes));
}

}  // namespace vox::fuzz
