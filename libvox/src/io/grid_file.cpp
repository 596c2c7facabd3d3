// Grid file encoding (docs/grid-format.md). Every read goes through ByteReader, which checks the remaining length
// before touching memory, so a truncated or corrupt file can only ever throw.
#include "vox/io/grid_file.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <limits>

#include "vox/io/atomic_file.h"
#include "vox/core/error.h"
#include "vox/io/input_file.h"
#include "io/byte_codec.h"
#include "io/grid_cell_table.h"
#include "io/grid_sections.h"

static_assert(std::endian::native == std::endian::little,
              "grid files are little-endian; big-endian hosts need byte swaps");

namespace vox {

namespace {

constexpr char kMagic[8] = {'V', 'O', 'X', 'G', 'R', 'I', 'D', '\n'};
constexpr size_t kHeaderSize = 32;  // magic, version, flags, payload size, checksum

// 64-bit multiplicative hash over 8-byte words: any change of one word changes the result (xor then multiply by an
// odd constant are bijections), and it runs at memory speed. Fed in pieces of any length, so a file can be summed
// as it is encoded; the payload size seeds it.
class ChecksumStream {
 public:
  explicit ChecksumStream(uint64_t size) : h_(0x9E3779B97F4A7C15ull ^ size) {}
  void update(std::string_view bytes) {
    size_t i = 0;
    if (carried_ > 0) {
      while (carried_ < 8 && i < bytes.size()) carry_[carried_++] = bytes[i++];
      if (carried_ < 8) return;
      word(carry_);
      carried_ = 0;
    }
    for (; i + 8 <= bytes.size(); i += 8) word(bytes.data() + i);
    for (; i < bytes.size(); ++i) carry_[carried_++] = bytes[i];
  }
  // The final 0-7 bytes, zero-extended to a word, end the sum.
  uint64_t value() const {
    uint64_t tail = 0;
    std::memcpy(&tail, carry_, carried_);
    uint64_t h = (h_ ^ tail) * 0x100000001B3ull;
    return h ^ (h >> 32);
  }

 private:
  void word(const char* p) {
    uint64_t w;
    std::memcpy(&w, p, 8);
    h_ = (h_ ^ w) * 0x100000001B3ull;
    h_ ^= h_ >> 29;
  }
  uint64_t h_;
  char carry_[8] = {};
  size_t carried_ = 0;
};

uint64_t wordChecksum(const char* data, size_t size) {
  ChecksumStream sum(size);
  sum.update({data, size});
  return sum.value();
}

void putMaterial(ByteWriter& w, const Material& m) {
  w.putString(m.name);
  w.putVec(m.diffuse);
  w.putVec(m.specular);
  w.put(m.exponent);
  w.putVec(m.reflective);
  w.putVec(m.transparent);
  w.put(m.indexOfRefraction);
}

Material getMaterial(ByteReader& r) {
  Material m;
  m.name = r.getString();
  m.diffuse = r.getVec("material colour");
  m.specular = r.getVec("material colour");
  m.exponent = r.getFinite("material exponent");
  m.reflective = r.getVec("material colour");
  m.transparent = r.getVec("material colour");
  m.indexOfRefraction = r.getFinite("material index of refraction");
  return m;
}

// Every optional section this build reads and writes, in the order they are written. Add new sections here.
const std::vector<SectionCodec>& sectionCodecs() {
  static const std::vector<SectionCodec> codecs = {
      {SectionTag::Textures, "textures", hasTexturesSection, putTexturesSection, getTexturesSection},
      {SectionTag::SolidTextures, "solid textures", hasSolidTexturesSection, putSolidTexturesSection,
       getSolidTexturesSection},
      {SectionTag::CameraSpan, "camera span", hasCameraSpanSection, putCameraSpanSection, getCameraSpanSection},
      {SectionTag::Distances, "distances", hasDistancesSection, putDistancesSection, getDistancesSection},
      {SectionTag::Fractions, "fractions", hasFractionsSection, putFractionsSection, getFractionsSection},
  };
  return codecs;
}

// `memos`: one per codec, kept by the caller across the passes of one write (SectionCodec::put).
using SectionMemos = std::vector<std::string>;

void putSections(ByteWriter& w, const Scene& scene, const Grid& grid, SectionMemos& memos) {
  memos.resize(sectionCodecs().size());
  for (size_t c = 0; c < sectionCodecs().size(); ++c) {
    const SectionCodec& codec = sectionCodecs()[c];
    if (!codec.has(scene, grid)) continue;
    // Its size comes before it, and a streaming writer cannot go back: the body is encoded twice, first only to
    // count its bytes (a copy of a section of hundreds of MB, grown by appending, took seconds).
    uint64_t size = 0;
    ByteWriter counter([&](std::string_view bytes) { size += bytes.size(); });
    codec.put(counter, scene, grid, memos[c]);
    counter.finish();
    w.put(uint32_t(codec.tag));
    w.put(size);
    codec.put(w, scene, grid, memos[c]);
  }
}

// Sections in strictly increasing tag order, as written (docs/grid-format.md "Sections"): a file has one encoding, and
// a later section's check may rely on an earlier one's content.
void getSections(ByteReader& r, Scene& scene, Grid& grid, const SectionContext& context) {
  std::vector<bool> seen(sectionCodecs().size(), false);
  const SectionCodec* previous = nullptr;
  while (!r.atEnd()) {
    const uint32_t tag = r.get<uint32_t>();
    const uint64_t size = r.get<uint64_t>();
    r.need(size);
    size_t c = 0;
    while (c < sectionCodecs().size() && uint32_t(sectionCodecs()[c].tag) != tag) ++c;
    if (c == sectionCodecs().size())
      r.corrupt("unknown section tag " + std::to_string(tag) + " (written by a newer libvox?)");
    const SectionCodec& codec = sectionCodecs()[c];
    if (seen[c]) r.corrupt(std::string("repeated ") + codec.name + " section");
    if (previous && uint32_t(previous->tag) > tag)
      r.corrupt(std::string(codec.name) + " section (tag " + std::to_string(tag) + ") after the " + previous->name +
                " section (tag " + std::to_string(uint32_t(previous->tag)) +
                "): sections must come in increasing tag order");
    seen[c] = true;
    previous = &codec;
    const size_t start = r.position();
    codec.get(r, scene, grid, context);
    if (r.position() - start != size) r.corrupt(std::string(codec.name) + " section does not match its size");
  }
}

// Version 1 stored one key per solid cell; runs are what the rest of libvox uses.
std::vector<CellRun> getSolidKeysAsRuns(ByteReader& r, uint64_t cells) {
  const size_t at = r.position();
  const std::vector<uint64_t> keys = r.getArray<uint64_t>("solid cell");
  std::vector<CellRun> runs;
  for (size_t c = 0; c < keys.size(); ++c) {
    if (keys[c] >= cells || (c > 0 && keys[c] <= keys[c - 1]))
      fail<InputError>(r.name(), ": cell table at byte ", at, ": solid cells not sorted");
    appendSolidKey(runs, keys[c]);
  }
  return runs;
}

}  // namespace

uint64_t gridChecksum(const char* payload, size_t size) { return wordChecksum(payload, size); }

namespace {

// The payload of docs/grid-format.md (everything after the 32-byte header), in `version` 3 (the cell table in
// `table`) or 2 (the flat arrays: tests of old files).
void encodePayload(ByteWriter& w, const Scene& scene, const Grid& grid, const EncodedCellTable& table, uint32_t version,
                   SectionMemos& memos) {
  // Scene.
  w.put(uint64_t(scene.materials.size()));
  for (const auto& m : scene.materials) putMaterial(w, m);
  w.put(uint64_t(scene.triangles.size()));
  for (const auto& t : scene.triangles) {
    for (const auto& v : t.v) w.putVec(v);
    w.put(t.material);
  }
  w.put(uint64_t(scene.spheres.size()));
  for (const auto& s : scene.spheres) {
    w.putVec(s.center);
    w.put(s.radius);
    for (const auto& row : s.transform.m)
      for (double x : row) w.put(x);
    w.put(s.material);
  }
  w.put(uint64_t(scene.planes.size()));
  for (const auto& p : scene.planes) {
    w.putVec(p.normal);
    w.put(p.offset);
    w.put(p.material);
  }
  w.put(uint8_t(scene.camera.has_value()));
  if (scene.camera) {
    const Camera& c = *scene.camera;
    w.put(uint8_t(c.kind));
    w.putVec(c.center);
    w.putVec(c.direction);
    w.putVec(c.up);
    w.put(c.fovDegrees);
    w.put(c.orthoHeight);
  }
  w.put(uint64_t(scene.lights.size()));
  for (const auto& l : scene.lights) {
    w.put(uint8_t(l.kind));
    w.putVec(l.direction);
    w.putVec(l.position);
    w.putVec(l.color);
    w.putVec(l.attenuation);
  }
  w.putVec(scene.background);
  w.putVec(scene.ambient);
  // Grid.
  w.putVec(grid.bounds.lo);
  w.putVec(grid.bounds.hi);
  for (uint32_t n : grid.dims) w.put(n);
  w.put(uint8_t(grid.method));
  if (version >= 3) {
    putCellTable(w, table);
  } else {
    w.putArray(grid.cellKeys);
    w.putArray(grid.cellStart);
    w.putArray(grid.primIds);
  }
  w.putArray(grid.outsidePrims);
  w.putArray(grid.solidRuns);
  putSections(w, scene, grid, memos);
}

std::string encodeHeader(uint64_t payloadSize, uint64_t checksum, uint32_t version = kGridFileVersion) {
  std::string header(kHeaderSize, '\0');
  const uint32_t flags = 0;
  std::memcpy(header.data(), kMagic, 8);
  std::memcpy(header.data() + 8, &version, 4);
  std::memcpy(header.data() + 12, &flags, 4);
  std::memcpy(header.data() + 16, &payloadSize, 8);
  std::memcpy(header.data() + 24, &checksum, 8);
  return header;
}

// Runs the encoder with every byte going to `sink`.
void streamPayload(const Scene& scene, const Grid& grid, const EncodedCellTable& table, SectionMemos& memos,
                   const ByteWriter::Sink& sink) {
  ByteWriter w(sink);
  encodePayload(w, scene, grid, table, gridFileVersionFor(grid), memos);
  w.finish();
}

}  // namespace

uint32_t gridFileVersionFor(const Grid& grid) {
  if (grid.sdfHalfWidth > 0) return 5;
  return grid.fractions.empty() ? 3 : 4;
}

std::string encodeGridFile(const Scene& scene, const Grid& grid, uint32_t version,
                           const std::function<bool(double)>& progress) {
  if (version == 0) version = gridFileVersionFor(grid);
  if (version < gridFileVersionFor(grid) && version >= 3)
    fail<UsageError>("grid file version ", version, " cannot hold ",
                     grid.sdfHalfWidth > 0 ? "this layout of distances" : "volume fractions");
  if (version < 2 || version > kGridFileVersion) fail<UsageError>("cannot write grid file version ", version);
  const EncodedCellTable table = version >= 3 ? encodeCellTable(grid, progress) : EncodedCellTable{};
  const uint64_t cellBytes = version >= 3 ? table.bytes.size() : grid.cellKeys.size() * 16 + grid.primIds.size() * 4;
  ByteWriter w;
  w.bytes().reserve(kHeaderSize + 256 + scene.triangles.size() * 76 + cellBytes + scene.materials.size() * 128);
  w.bytes().assign(kHeaderSize, '\0');  // the header is filled in last, in place, so the payload is never copied
  SectionMemos memos;
  encodePayload(w, scene, grid, table, version, memos);
  std::string bytes = std::move(w.bytes());
  const uint64_t payloadSize = bytes.size() - kHeaderSize;
  const std::string header = encodeHeader(payloadSize, wordChecksum(bytes.data() + kHeaderSize, payloadSize), version);
  std::memcpy(bytes.data(), header.data(), kHeaderSize);
  return bytes;
}

namespace {

// The 32-byte header: magic, version (returned), flags, payload size and checksum, checked against the bytes.
uint32_t checkHeader(const std::string& bytes, const std::string& name) {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    fail<InputError>(name, ": not a libvox grid file (bad magic number)");
  ByteReader header(bytes, 8, name);
  const uint32_t version = header.get<uint32_t>();
  if (version > kGridFileVersion)
    fail<InputError>(name, ": grid file version ", version, " is newer than this build reads (", kGridFileVersion, ")");
  if (version == 0) fail<InputError>(name, ": byte 8: invalid grid file version 0");
  if (header.get<uint32_t>() != 0) fail<InputError>(name, ": byte 12: unknown flags (written by a newer version?)");
  const uint64_t payloadSize = header.get<uint64_t>();
  const uint64_t expected = header.get<uint64_t>();
  if (payloadSize != bytes.size() - kHeaderSize) {
    if (payloadSize > bytes.size() - kHeaderSize)
      fail<InputError>(name, ": truncated at byte ", bytes.size(), " (header promises ", payloadSize + kHeaderSize,
                       " bytes)");
    fail<InputError>(name, ": ", bytes.size() - kHeaderSize - payloadSize,
                     " unexpected bytes after the end of the grid");
  }
  if (wordChecksum(bytes.data() + kHeaderSize, payloadSize) != expected)
    fail<InputError>(name, ": checksum mismatch: the file is corrupt");
  return version;
}

// Materials and primitives of the payload, each primitive's material index checked.
void getPrimitives(ByteReader& r, Scene& scene) {
  const uint64_t nMaterials = r.getCount(4 + 14 * 8, "material");
  for (uint64_t i = 0; i < nMaterials; ++i) scene.materials.push_back(getMaterial(r));
  auto material = [&](uint32_t m) {
    if (m >= nMaterials) r.corrupt("material index " + std::to_string(m) + " out of range");
    return m;
  };
  scene.triangles.resize(r.getCount(9 * 8 + 4, "triangle"));
  for (auto& t : scene.triangles) {
    for (auto& v : t.v) v = r.getVec("vertex");
    t.material = material(r.get<uint32_t>());
  }
  scene.spheres.resize(r.getCount(20 * 8 + 4, "sphere"));
  for (auto& s : scene.spheres) {
    s.center = r.getVec("sphere centre");
    s.radius = r.getFinite("sphere radius");
    if (!(s.radius > 0)) r.corrupt("sphere radius is not positive");
    for (auto& row : s.transform.m)
      for (double& x : row) x = r.getFinite("sphere transform");
    s.material = material(r.get<uint32_t>());
  }
  scene.planes.resize(r.getCount(4 * 8 + 4, "plane"));
  for (auto& p : scene.planes) {
    p.normal = r.getVec("plane normal");
    p.offset = r.getFinite("plane offset");
    p.material = material(r.get<uint32_t>());
  }
}

// Camera, lights, background and ambient light.
void getView(ByteReader& r, Scene& scene) {
  const uint8_t hasCamera = r.get<uint8_t>();
  if (hasCamera > 1) r.corrupt("invalid camera flag");
  if (hasCamera) {
    Camera c;
    const uint8_t kind = r.get<uint8_t>();
    if (kind > 1) r.corrupt("unknown camera kind " + std::to_string(kind));
    c.kind = CameraKind(kind);
    c.center = r.getVec("camera");
    c.direction = r.getVec("camera");
    c.up = r.getVec("camera");
    c.fovDegrees = r.getFinite("camera field of view");
    c.orthoHeight = r.getFinite("camera size");
    scene.camera = c;
  }
  scene.lights.resize(r.getCount(1 + 12 * 8, "light"));
  for (auto& l : scene.lights) {
    const uint8_t kind = r.get<uint8_t>();
    if (kind > 1) r.corrupt("unknown light kind " + std::to_string(kind));
    l.kind = LightKind(kind);
    l.direction = r.getVec("light");
    l.position = r.getVec("light");
    l.color = r.getVec("light");
    l.attenuation = r.getVec("light");
  }
  scene.background = r.getVec("background");
  scene.ambient = r.getVec("ambient");
}

// Bounds, dims (checked against the cell boundary formula) and overlap method.
void getGridShape(ByteReader& r, Grid& grid) {
  grid.bounds.lo = r.getVec("bounds");
  grid.bounds.hi = r.getVec("bounds");
  for (int a = 0; a < 3; ++a)
    if (!(grid.bounds.lo[a] < grid.bounds.hi[a])) r.corrupt("empty grid bounds");
  for (auto& n : grid.dims) {
    n = r.get<uint32_t>();
    if (n == 0 || n > (1u << 21)) r.corrupt("grid dimension " + std::to_string(n) + " out of range");
  }
  for (int a = 0; a < 3; ++a)
    if (cellBoundary(grid.bounds, grid.dims, a, grid.dims[a]) != grid.bounds.hi[a])
      r.corrupt("grid bounds do not match the cell boundary formula");
  const uint8_t method = r.get<uint8_t>();
  if (method > uint8_t(OverlapMethod::Exact)) r.corrupt("unknown overlap method " + std::to_string(method));
  grid.method = OverlapMethod(method);
}

// Where the version 3 cell table starting at `at` ends, by its byte count (the file's end when that is cut off or
// past it; getCellTable refuses such a table): only to scale the table's progress.
size_t cellTableEnd(const std::string& bytes, size_t at) {
  uint64_t size = 0;
  if (bytes.size() < at || bytes.size() - at < 24) return bytes.size();
  std::memcpy(&size, bytes.data() + at + 16, 8);
  return size > bytes.size() - at - 24 ? bytes.size() : at + 24 + size;
}

// Structural checks of a version 1 or 2 cell table read at byte `cellsAt` (version 3's decoder checks the same as
// it reads): sorted unique keys inside the grid, offsets that partition the references, ids below `bounded` (the
// triangles and spheres).
void checkFlatCellTable(const Grid& grid, uint64_t bounded, const std::string& name, size_t cellsAt) {
  auto bad = [&](const std::string& what) { fail<InputError>(name, ": cell table at byte ", cellsAt, ": ", what); };
  const uint64_t cells = grid.cellCount();
  for (size_t c = 0; c < grid.cellKeys.size(); ++c)
    if (grid.cellKeys[c] >= cells || (c > 0 && grid.cellKeys[c] <= grid.cellKeys[c - 1]))
      bad("cell keys not sorted or outside the grid");
  if (grid.cellStart.size() != grid.cellKeys.size() + 1) bad("cell offsets do not match the cell count");
  if (grid.cellStart.front() != 0 || grid.cellStart.back() != grid.primIds.size())
    bad("cell offsets do not cover the references");
  // Every offset is checked before any primitive range is walked: offsets that run backwards or past the
  // references would otherwise send the walk outside primIds.
  for (size_t c = 0; c + 1 < grid.cellStart.size(); ++c)
    if (grid.cellStart[c + 1] <= grid.cellStart[c] || grid.cellStart[c + 1] > grid.primIds.size())
      bad("cell " + std::to_string(c) + ": offsets empty, backwards or past the references");
  for (size_t c = 0; c + 1 < grid.cellStart.size(); ++c) {
    for (uint64_t k = grid.cellStart[c]; k < grid.cellStart[c + 1]; ++k)
      if (grid.primIds[k] >= bounded || (k > grid.cellStart[c] && grid.primIds[k] <= grid.primIds[k - 1]))
        bad("primitive ids not ascending or out of range");
  }
}

}  // namespace

GridFile decodeGridFile(const std::string& bytes, const std::string& name,
                        const std::function<bool(double)>& progress) {
  const uint32_t version = checkHeader(bytes, name);
  ByteReader r(bytes, kHeaderSize, name);
  GridFile out;
  Scene& scene = out.scene;
  getPrimitives(r, scene);
  getView(r, scene);
  Grid& grid = out.grid;
  getGridShape(r, grid);

  const uint64_t bounded = scene.triangles.size() + scene.spheres.size();
  const size_t cellsAt = r.position();
  // Progress is the fraction of the file read, so that the cell table and the sections after it (the distance band
  // is as large) ask in one increasing sequence.
  const auto fileFraction = [&](size_t position) { return double(position) / double(bytes.size()); };
  if (version >= 3) {
    const size_t tableEnd = cellTableEnd(bytes, cellsAt);
    std::function<bool(double)> tableProgress;
    if (progress)
      tableProgress = [&](double f) {
        return progress(fileFraction(cellsAt) + f * (fileFraction(tableEnd) - fileFraction(cellsAt)));
      };
    getCellTable(r, grid, bounded, tableProgress);
  } else {
    grid.cellKeys = r.getArray<uint64_t, HugeVector<uint64_t>>("cell");
    grid.cellStart = r.getArray<uint64_t, HugeVector<uint64_t>>("cell start");
    grid.primIds = r.getArray<uint32_t, HugeVector<uint32_t>>("reference");
  }
  const size_t outsideAt = r.position();
  grid.outsidePrims = r.getArray<uint32_t>("outside primitive");
  for (uint32_t id : grid.outsidePrims)
    if (id >= bounded) fail<InputError>(name, ": byte ", outsideAt, ": outside primitive id out of range");
  const uint64_t cells = grid.cellCount();
  if (version == 1) {
    grid.solidRuns = getSolidKeysAsRuns(r, cells);
    if (!r.atEnd()) r.corrupt("unexpected bytes after the solid cells");
  } else {
    const size_t runsAt = r.position();
    grid.solidRuns = r.getArray<CellRun>("solid run");
    checkSolidRuns(grid.solidRuns, cells, name + ": solid runs at byte " + std::to_string(runsAt));
    getSections(r, scene, grid, SectionContext{version, progress, bytes.size()});
    if (version < 4 && gridFileVersionFor(grid) >= 4)
      fail<InputError>(name, ": distances or volume fractions in a version ", version, " file (they need version 4)");
  }
  if (version < 3) checkFlatCellTable(grid, bounded, name, cellsAt);
  checkSolidRunsMissCells(grid.cellKeys, grid.solidRuns, name + ": solid runs");
  // The same checks as at import (singular ellipsoid transforms, cameras that cannot form an image, materials),
  // so a grid file that passes here traces and exports.
  validateScene(scene, name);
  return out;
}

void writeGridFile(const std::string& path, const Scene& scene, const Grid& grid, WriteTimes* times,
                   const std::function<bool(double)>& progress) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  checkGridBeforeWrite(grid, path);  // before the output is opened: nothing is written that a reader refuses
  // Asked at every 64 KiB chunk of each pass (the sinks below): a 2048^3 grid's file took 1.75 s past Ctrl-C before.
  const auto ask = [&](double f) {
    if (progress && !progress(f)) fail<Error>(path, ": write cancelled");
  };
  // Three passes over the encoding instead of the whole file in memory (at 1024^3 the file is as large as the grid):
  // the size, which seeds the checksum; the checksum; then the bytes, header first, through a temporary file.
  // The cell table, the bulk of the file, is encoded once.
  const EncodedCellTable table = encodeCellTable(grid, [&](double f) { return !progress || progress(0.1 * f); });
  ask(0.1);
  uint64_t size = 0;
  SectionMemos memos;
  streamPayload(scene, grid, table, memos, [&](std::string_view bytes) {
    size += bytes.size();
    ask(0.1);
  });
  const double total = double(std::max<uint64_t>(size, 1));
  ChecksumStream sum(size);
  uint64_t done = 0;
  streamPayload(scene, grid, table, memos, [&](std::string_view bytes) {
    sum.update(bytes);
    ask(0.1 + 0.3 * double(done += bytes.size()) / total);
  });
  OutputFile out(path);
  out.write(encodeHeader(size, sum.value(), gridFileVersionFor(grid)));
  done = 0;
  streamPayload(scene, grid, table, memos, [&](std::string_view bytes) {
    out.write(bytes);
    ask(0.4 + 0.6 * double(done += bytes.size()) / total);
  });
  out.flush();
  const auto written = Clock::now();
  out.commit();
  if (times) {
    times->writeSeconds = std::chrono::duration<double>(written - start).count();
    times->syncSeconds = std::chrono::duration<double>(Clock::now() - written).count();
  }
}

GridFile readGridFile(const std::string& path, const std::function<bool(double)>& progress) {
  // readInputFile refuses non-regular files and sizes the memory budget cannot hold, before reading them whole.
  const auto part = [&](double from, double to) -> std::function<bool(double)> {
    if (!progress) return {};
    return [&progress, from, to](double f) { return progress(from + (to - from) * f); };
  };
  return decodeGridFile(readInputFile(path, "grid file", part(0, 0.3)), path, part(0.3, 1));
}

}  // namespace vox
