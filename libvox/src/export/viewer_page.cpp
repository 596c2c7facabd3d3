// The viewer page (viewer_page.h): the binary layout of docs/viewer-format.md and the HTML around it. Pure data
// here except writeViewerPage, which streams the page into an OutputFile.
#include "vox/export/viewer_page.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <type_traits>
#include <unordered_map>

#include <zlib.h>

#include "vox/core/error.h"
#include "vox/core/exact_number.h"
#include "vox/export/level_surface.h"
#include "vox/io/atomic_file.h"

#ifdef VOX_HAVE_VIEWER_SCRIPT
// Generated at build time by viewer/build.mjs (CMake option VOX_VIEWER): three.js and viewer/src, minified.
namespace vox::viewer_script {
extern const char kText[];
extern const size_t kSize;
}  // namespace vox::viewer_script
#endif

namespace vox {

namespace {

// Little-endian appends; the layout's arrays start at multiples of 8 (so the page can view them as typed arrays).
struct ByteWriter {
  std::string bytes;

  template <typename T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    bytes.append(raw, sizeof(T));
  }
  template <typename T>
  void putAt(size_t offset, T value) {
    VOX_CHECK(offset + sizeof(T) <= bytes.size());
    std::memcpy(bytes.data() + offset, &value, sizeof(T));
  }
  void align() { bytes.resize((bytes.size() + 7) / 8 * 8, '\0'); }
  // Values of `width` bytes (1, 2 or 4), each known to fit.
  void putUint(uint32_t value, uint32_t width) {
    if (width == 1)
      put(uint8_t(value));
    else if (width == 2)
      put(uint16_t(value));
    else
      put(value);
  }
};

static_assert(std::endian::native == std::endian::little, "the viewer layout is written by memcpy");

uint32_t widthFor(uint64_t largest) { return largest <= 0xff ? 1 : largest <= 0xffff ? 2 : 4; }
uint32_t widthCode(uint32_t width) { return width == 1 ? 0 : width == 2 ? 1 : 2; }

uint32_t checked32(uint64_t n, const char* what) {
  if (n > std::numeric_limits<uint32_t>::max())
    fail<LimitError>("viewer page: ", n, " ", what, " exceed the page's 32-bit counts (at most 4294967295)");
  return uint32_t(n);
}

uint32_t packRgb(const Rgb8& c) { return uint32_t(c[0]) << 16 | uint32_t(c[1]) << 8 | c[2]; }

// The lattice coordinate of a surface vertex on `axis`: positions come from cellBoundary, so the nearest index
// reproduces them exactly (checked: a mismatch would put the page's surface off the cells).
uint32_t latticeIndex(const Grid& grid, int axis, double x) {
  const double lo = grid.bounds.lo[axis], hi = grid.bounds.hi[axis];
  const double n = grid.dims[axis];
  const double t = std::round((x - lo) / (hi - lo) * n);
  VOX_CHECK(t >= 0 && t <= n);
  const auto i = uint32_t(t);
  VOX_CHECK(cellBoundary(grid.bounds, grid.dims, axis, i) == x);
  return i;
}

std::string htmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Ctrl-C for a page (ViewerPageOptions::progress): the serial loops ask every 2^16 steps, the deflate every 4 MiB;
// a page of the bunny at 512^3 ran 6.6 s without asking. Throws Error("viewer page cancelled") once told to stop.
struct PageCancel {
  const std::function<bool(double)>& progress;
  void operator()(double fraction) const {
    if (progress && !progress(fraction)) fail<Error>("viewer page cancelled");
  }
  void step(size_t i, double fraction) const {
    if ((i & 0xffff) == 0) (*this)(fraction);
  }
};

constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void appendBase64(std::string& out, std::string_view data) {
  const size_t start = out.size();
  out.resize(start + (data.size() + 2) / 3 * 4);
  char* o = out.data() + start;
  size_t i = 0;
  for (; i + 3 <= data.size(); i += 3) {
    const uint32_t v = uint32_t(uint8_t(data[i])) << 16 | uint32_t(uint8_t(data[i + 1])) << 8 | uint8_t(data[i + 2]);
    *o++ = kBase64[v >> 18];
    *o++ = kBase64[(v >> 12) & 63];
    *o++ = kBase64[(v >> 6) & 63];
    *o++ = kBase64[v & 63];
  }
  if (i < data.size()) {
    const bool two = i + 1 < data.size();
    const uint32_t v = uint32_t(uint8_t(data[i])) << 16 | (two ? uint32_t(uint8_t(data[i + 1])) << 8 : 0u);
    *o++ = kBase64[v >> 18];
    *o++ = kBase64[(v >> 12) & 63];
    *o++ = two ? kBase64[(v >> 6) & 63] : '=';
    *o++ = '=';
  }
}

#ifdef VOX_HAVE_VIEWER_SCRIPT
// `bytes` as one zlib stream (level 1: three times smaller for a third of the time of level 6 on these layouts).
std::string deflateBytes(std::string_view bytes, const PageCancel& cancel) {
  z_stream z{};
  if (deflateInit(&z, 1) != Z_OK) fail<LimitError>("viewer page: cannot start zlib");
  std::string out(deflateBound(&z, uLong(bytes.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  // zlib counts in uInt, and a step is asked whether to go on: feed at most 4 MiB at a time (about 40 ms).
  constexpr size_t kStep = size_t(4) << 20;
  size_t inLeft = bytes.size();
  int status = Z_OK;
  while (status == Z_OK) {
    try {
      cancel(0.8 + 0.15 * double(bytes.size() - inLeft) / double(std::max<size_t>(bytes.size(), 1)));
    } catch (...) {
      deflateEnd(&z);
      throw;
    }
    const size_t in = std::min(inLeft, kStep);
    z.avail_in = uInt(in);
    z.avail_out = uInt(std::min(out.size() - z.total_out, size_t(1) << 30));
    status = deflate(&z, in == inLeft ? Z_FINISH : Z_NO_FLUSH);
    inLeft -= in - z.avail_in;
  }
  deflateEnd(&z);
  if (status != Z_STREAM_END) fail<LimitError>("viewer page: zlib failed (", status, ")");
  out.resize(z.total_out);
  return out;
}
#endif

// Bytes of data per <script> element: a multiple of 3 (so each element is base64 on its own), small enough that no
// browser meets a string-length limit decoding one.
constexpr size_t kChunkBytes = size_t(48) << 20;

// The page in pieces, handed to `sink` in order (writeViewerPage streams them, viewerPageHtml concatenates).
template <typename Sink>
void emitPage(std::string_view data, const std::string& title, const PageCancel& cancel, Sink&& sink) {
#ifdef VOX_HAVE_VIEWER_SCRIPT
  const std::string name = htmlEscape(title.empty() ? std::string("grid") : title);
  sink(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      // No fetch of any kind: the page is its own world (an inline module and inline styles only).
      "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'unsafe-inline'; "
      "style-src 'unsafe-inline'; img-src data: blob:\">\n"
      "<meta name=\"generator\" content=\"vox-export viewer, data layout " +
      std::to_string(kViewerDataVersion) + "\">\n<title>" + name + " - libvox viewer</title>\n</head>\n<body>\n");
  // The layout deflated (a zlib stream, RFC 1950; the page inflates it with DecompressionStream): about a third of
  // its size, which the browser parses three times faster.
  const std::string packed = deflateBytes(data, cancel);
  std::string chunk;
  for (size_t at = 0; at < packed.size(); at += kChunkBytes) {
    chunk = "<script type=\"application/x-vox-data\" data-encoding=\"deflate\" data-bytes=\"" +
            std::to_string(data.size()) + "\">";
    appendBase64(chunk, std::string_view(packed).substr(at, kChunkBytes));
    chunk += "</script>\n";
    sink(std::string_view(chunk));
    cancel(0.95);
  }
  sink("<script type=\"module\">\n");
  sink(std::string_view(viewer_script::kText, viewer_script::kSize));
  sink("\n</script>\n</body>\n</html>\n");
#else
  (void)data, (void)title, (void)cancel, (void)sink;
  fail<UsageError>(
      "this vox-export was built without the viewer page (CMake option VOX_VIEWER=OFF, or Node.js and npm were "
      "missing at build time)");
#endif
}

// The signed-distance band in the layout's row form (the occupied cells' form): rows (j, k) ascending, each cell's i.
struct BandRows {
  std::vector<uint32_t> keys, start, i;
};

// Refuses a band or fractions that do not fit the grid (a reader of the page would index past its arrays).
void checkFields(const Grid& grid) {
  const uint64_t cells = uint64_t(grid.dims[0]) * grid.dims[1] * grid.dims[2];
  if (grid.sdfKeys.size() != grid.sdfValues.size())
    fail<InputError>("grid: ", grid.sdfKeys.size(), " signed-distance keys but ", grid.sdfValues.size(), " values");
  if (!(grid.sdfHalfWidth >= 0) || (grid.sdfHalfWidth == 0 && !grid.sdfKeys.empty()))
    fail<InputError>("grid: signed distances with a band half-width of ", exactNumber(grid.sdfHalfWidth), " cells");
  for (size_t b = 0; b < grid.sdfKeys.size(); ++b)
    if (grid.sdfKeys[b] >= cells || (b > 0 && grid.sdfKeys[b] <= grid.sdfKeys[b - 1]))
      fail<InputError>("grid: signed-distance keys not ascending inside the grid (key ", grid.sdfKeys[b], ")");
  if (!grid.fractions.empty() && grid.fractions.size() != grid.cellKeys.size())
    fail<InputError>("grid: ", grid.fractions.size(), " volume fractions for ", grid.cellKeys.size(),
                     " occupied cells");
}

BandRows bandRows(const Grid& grid) {
  BandRows rows;
  const uint32_t nBand = checked32(grid.sdfKeys.size(), "signed-distance cells");
  rows.i.reserve(nBand);
  for (uint32_t b = 0; b < nBand; ++b) {
    const uint64_t key = grid.sdfKeys[b];
    const auto row = uint32_t(key / grid.dims[0]);  // < ny * nz, checked to fit
    if (rows.keys.empty() || rows.keys.back() != row) {
      rows.keys.push_back(row);
      rows.start.push_back(b);
    }
    rows.i.push_back(uint32_t(key % grid.dims[0]));
  }
  rows.start.push_back(nBand);
  return rows;
}

// The band (rows, each cell's i, the distances) and the fractions, as float32: the page shows colours and a read-out
// of 7 significant digits, so half the bytes of doubles.
void putFields(ByteWriter& w, const Grid& grid, const BandRows& band, bool hasBand, uint32_t coordWidth) {
  if (hasBand) {
    for (uint32_t r : band.keys) w.put(r);
    w.align();
    for (uint32_t s : band.start) w.put(s);
    w.align();
    for (uint32_t i : band.i) w.putUint(i, coordWidth);
    w.align();
    for (double v : grid.sdfValues) w.put(float(v));
    w.align();
  }
  for (double f : grid.fractions) w.put(float(f));
  w.align();
}

}  // namespace

bool viewerPageAvailable() {
#ifdef VOX_HAVE_VIEWER_SCRIPT
  return true;
#else
  return false;
#endif
}

std::string encodeViewerData(const Grid& grid, const Scene& scene, const ViewerPageOptions& options,
                             ViewerDataStats* stats) {
  const size_t nOcc = grid.cellKeys.size();
  if (grid.cellStart.size() != nOcc + 1 || grid.cellStart.back() > grid.primIds.size())
    fail<InputError>("grid: inconsistent cell table (", nOcc, " cells, ", grid.cellStart.size(), " offsets)");
  const auto& dims = grid.dims;
  checked32(uint64_t(dims[1]) * dims[2], "rows of cells (ny * nz)");
  checked32(nOcc, "occupied cells");
  checked32(grid.solidRuns.size(), "solid runs");
  checkFields(grid);
  // A band (even an empty one: the grid was asked for distances) and fractions add flag bits 8 and 9 and arrays at
  // the end; without them the layout is the one pages had before.
  const bool hasBand = grid.sdfHalfWidth > 0;
  const bool hasFractions = !grid.fractions.empty();
  const BandRows band = hasBand ? bandRows(grid) : BandRows{};
  const bool colors = options.color != ColorMode::None;
  const bool wide = std::max({dims[0], dims[1], dims[2]}) > 0xffff;
  const uint32_t coordWidth = wide ? 4 : 2;

  // The merged surface, as triangles; each (vertex, colour) pair becomes one vertex of the page's mesh.
  const PageCancel cancel{options.progress};
  const auto share = [&](double from, double span) {
    return [&, from, span](double f) { return !options.progress || options.progress(from + span * f); };
  };
  const VoxelMesh mesh = triangulateVoxelMesh(
      buildVoxelMesh(grid, scene, FaceMode::Merged, options.color, nullptr, share(0, 0.4)), share(0.4, 0.1));
  cancel(0.5);
  std::vector<uint32_t> remap(mesh.vertexCount(), std::numeric_limits<uint32_t>::max());
  std::vector<uint32_t> remapColor(mesh.vertexCount(), 0);
  std::unordered_map<uint64_t, uint32_t> extra;  // vertex * 2^24 + colour -> page vertex, for 2nd and later colours
  std::vector<uint32_t> pageVertexSource;        // page vertex -> mesh vertex
  std::vector<uint32_t> pageVertexColor;         // page vertex -> packed RGB
  std::vector<uint32_t> triangles(mesh.faceVertices.size());
  for (size_t f = 0; f < mesh.faceCount(); ++f) {
    cancel.step(f, 0.5);
    const uint32_t color = colors ? packRgb(mesh.faceColors[f]) : 0;
    for (uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      const uint32_t v = mesh.faceVertices[c];
      uint32_t index;
      if (remap[v] == std::numeric_limits<uint32_t>::max()) {
        index = remap[v] = checked32(pageVertexSource.size(), "surface vertices");
        remapColor[v] = color;
        pageVertexSource.push_back(v);
        pageVertexColor.push_back(color);
      } else if (remapColor[v] == color) {
        index = remap[v];
      } else {
        const auto [it, added] = extra.try_emplace(uint64_t(v) << 24 | color, uint32_t(pageVertexSource.size()));
        if (added) {
          checked32(pageVertexSource.size(), "surface vertices");
          pageVertexSource.push_back(v);
          pageVertexColor.push_back(color);
        }
        index = it->second;
      }
      triangles[c] = index;
    }
  }
  checked32(mesh.faceCount(), "surface triangles");

  // The cells' colours as a palette (sorted, so the layout does not depend on thread timing).
  std::vector<uint32_t> cellColor;
  std::vector<uint32_t> palette;
  if (colors) {
    const std::vector<Rgb8> rgb = occupiedCellColors(grid, scene, options.color, 0, share(0.55, 0.1));
    std::map<uint32_t, uint32_t> index;
    for (size_t c = 0; c < nOcc; ++c) {
      cancel.step(c, 0.65);
      index.emplace(packRgb(rgb[c]), 0);
    }
    for (auto& [color, i] : index) {
      i = uint32_t(palette.size());
      palette.push_back(color);
    }
    cellColor.resize(nOcc);
    for (size_t c = 0; c < nOcc; ++c) {
      cancel.step(c, 0.7);
      cellColor[c] = index[packRgb(rgb[c])];
    }
  }

  // Rows (j, k) of occupied cells; the keys are sorted, so rows come in order.
  std::vector<uint32_t> rowKeys, rowStart;
  uint32_t maxCount = 0;
  uint64_t idCount = 0;
  for (size_t c = 0; c < nOcc; ++c) {
    cancel.step(c, 0.7);
    const uint64_t row = grid.cellKeys[c] / dims[0];
    if (rowKeys.empty() || rowKeys.back() != row) {
      rowKeys.push_back(uint32_t(row));
      rowStart.push_back(uint32_t(c));
    }
    const uint64_t count = grid.cellStart[c + 1] - grid.cellStart[c];
    maxCount = std::max(maxCount, checked32(count, "primitives in one cell"));
    idCount += std::min<uint64_t>(count, options.idsPerCell);
  }
  rowStart.push_back(uint32_t(nOcc));
  checked32(idCount, "primitive ids");
  const uint32_t countWidth = widthFor(maxCount);
  const uint32_t paletteWidth = widthFor(palette.empty() ? 0 : palette.size() - 1);

  // The level surface (issue 47, flag bit 10): the band's level set 0 as vox-export --surface writes it, which the
  // page shows beside the voxels; only when the band holds level 0 (largestSurfaceLevel, else --surface refuses).
  const bool hasLevel = hasBand && largestSurfaceLevel(grid) >= 0;
  const VoxelMesh level = hasLevel ? extractLevelSurface(grid, 0.0, nullptr, share(0.7, 0.05)) : VoxelMesh{};
  cancel(0.75);

  const Camera camera = scene.camera ? *scene.camera : defaultCamera(grid.bounds);
  const Vec3 centre = (grid.bounds.lo + grid.bounds.hi) * 0.5;
  const std::string title = options.title;

  ByteWriter w;
  w.bytes.reserve(kViewerHeaderBytes + pageVertexSource.size() * (3 * coordWidth + 3) + triangles.size() * 4 +
                  nOcc * (coordWidth + countWidth + paletteWidth) + idCount * 4 +
                  (band.keys.size() + band.start.size()) * 4 + band.i.size() * (coordWidth + 4) +
                  grid.fractions.size() * 4 + level.vertexCount() * 12 + level.faceVertices.size() * 4 + 16);
  w.bytes.append("VOXVIEW", 8);  // with its terminating zero
  w.put(kViewerDataVersion);
  const uint32_t flags = (colors ? 1u : 0u) | (wide ? 2u : 0u) | widthCode(countWidth) << 2 |
                         widthCode(paletteWidth) << 4 | (camera.kind == CameraKind::Orthographic ? 64u : 0u) |
                         (camera.span == CameraSpan::LongerSide ? 128u : 0u) | (hasBand ? 256u : 0u) |
                         (hasFractions ? 512u : 0u) | (hasLevel ? 1024u : 0u);
  w.put(flags);
  for (int a = 0; a < 3; ++a) w.put(grid.bounds.lo[a]);
  for (int a = 0; a < 3; ++a) w.put(grid.bounds.hi[a]);
  for (int a = 0; a < 3; ++a) w.put(dims[a]);
  w.put(uint32_t(options.color == ColorMode::Count ? 0 : options.color == ColorMode::Material ? 1 : 2));
  for (int a = 0; a < 3; ++a) w.put(camera.center[a]);
  for (int a = 0; a < 3; ++a) w.put(camera.direction[a]);
  for (int a = 0; a < 3; ++a) w.put(camera.up[a]);
  w.put(camera.fovDegrees);
  w.put(camera.orthoHeight);
  for (int a = 0; a < 3; ++a) w.put(float(scene.background[a]));
  for (uint8_t c : kSolidCellColor) w.put(c);
  w.put(uint8_t(0));
  w.put(maxCount);
  w.put(uint32_t(pageVertexSource.size()));
  w.put(uint32_t(mesh.faceCount()));
  w.put(uint32_t(palette.size()));
  w.put(uint32_t(rowKeys.size()));
  w.put(uint32_t(nOcc));
  w.put(uint32_t(grid.solidRuns.size()));
  w.put(options.idsPerCell);
  w.put(uint32_t(idCount));
  w.put(checked32(scene.triangles.size(), "scene triangles"));
  w.put(checked32(scene.spheres.size(), "scene spheres"));
  w.put(checked32(scene.primitiveCount(), "primitives"));
  w.put(checked32(title.size(), "title bytes"));
  w.put(checked32(scene.planes.size(), "scene planes"));
  if (hasBand) {
    w.put(uint32_t(grid.sdfKeys.size()));  // checked by bandRows
    w.put(uint32_t(band.keys.size()));
    w.put(grid.sdfHalfWidth);
  }
  VOX_CHECK(w.bytes.size() <= kViewerHeaderBytes);
  w.bytes.resize(kViewerHeaderBytes, '\0');

  w.bytes += title;
  w.align();
  for (size_t n = 0; n < pageVertexSource.size(); ++n) {
    cancel.step(n, 0.75);
    for (int a = 0; a < 3; ++a) w.putUint(latticeIndex(grid, a, mesh.positions[pageVertexSource[n]][a]), coordWidth);
  }
  w.align();
  if (colors) {
    for (uint32_t c : pageVertexColor) w.put(uint8_t(c >> 16)), w.put(uint8_t(c >> 8)), w.put(uint8_t(c));
    w.align();
  }
  for (uint32_t t : triangles) w.put(t);
  w.align();
  cancel(0.75);  // each loop below over at most the cells: tens of milliseconds
  if (colors) {
    for (uint32_t c : palette) w.put(uint8_t(c >> 16)), w.put(uint8_t(c >> 8)), w.put(uint8_t(c));
    w.align();
  }
  for (uint32_t r : rowKeys) w.put(r);
  w.align();
  for (uint32_t s : rowStart) w.put(s);
  w.align();
  for (uint64_t key : grid.cellKeys) w.putUint(uint32_t(key % dims[0]), coordWidth);
  w.align();
  cancel(0.75);
  for (size_t c = 0; c < nOcc; ++c) w.putUint(uint32_t(grid.cellStart[c + 1] - grid.cellStart[c]), countWidth);
  w.align();
  if (colors) {
    for (uint32_t i : cellColor) w.putUint(i, paletteWidth);
    w.align();
  }
  for (size_t c = 0; c < nOcc; ++c) {
    const auto prims = grid.cellPrims(c);
    for (size_t i = 0; i < std::min<size_t>(prims.size(), options.idsPerCell); ++i) w.put(prims[i]);
  }
  w.align();
  cancel(0.75);
  for (const CellRun& run : grid.solidRuns) {
    // Keys up to 2^53 are exact in a double; larger grids do not exist (2^53 cells).
    VOX_CHECK(run.first + run.count <= (uint64_t(1) << 53));
    w.put(double(run.first));
    w.put(double(run.count));
  }
  w.align();
  for (const Triangle& t : scene.triangles)
    for (const Vec3& v : t.v)
      for (int a = 0; a < 3; ++a) w.put(float(v[a] - centre[a]));
  w.align();
  for (const Sphere& s : scene.spheres) {
    // Unit sphere to world: transform * translate(center) * scale(radius), then moved by -centre; rows 0..2.
    Mat4 m = s.transform * translation(s.center) * scaling({s.radius, s.radius, s.radius});
    for (int r = 0; r < 3; ++r) m.m[r][3] -= centre[r];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) w.put(float(m.m[r][c]));
  }
  w.align();
  putFields(w, grid, band, hasBand, coordWidth);
  if (hasLevel) {
    // Counts checked by extractLevelSurface (at most 2^32 - 1); positions as the scene's triangles: float, relative
    // to the bounds' centre (the surface's vertices lie between cell centres, not on the lattice of boundaries).
    w.put(uint32_t(level.vertexCount()));
    w.put(uint32_t(level.faceCount()));
    for (const Vec3& p : level.positions)
      for (int a = 0; a < 3; ++a) w.put(float(p[a] - centre[a]));
    w.align();
    for (uint32_t v : level.faceVertices) w.put(v);
    w.align();
  }

  if (stats) {
    stats->voxels = nOcc + grid.solidCount();  // a grid's cells are occupied or solid, never both
    stats->surfaceVertices = pageVertexSource.size();
    stats->surfaceTriangles = mesh.faceCount();
    stats->storedIds = idCount;
    stats->levelVertices = level.vertexCount();
    stats->levelTriangles = level.faceCount();
    stats->dataBytes = w.bytes.size();
  }
  return std::move(w.bytes);
}

std::string viewerPageHtml(std::string_view data, const std::string& title) {
  std::string html;
  const std::function<bool(double)> none;
  emitPage(data, title, PageCancel{none}, [&](std::string_view piece) { html += piece; });
  return html;
}

void writeViewerPage(const std::string& path, const Grid& grid, const Scene& scene, const ViewerPageOptions& options,
                     ViewerDataStats* stats) {
  if (!viewerPageAvailable()) viewerPageHtml({}, {});  // throws the UsageError before any work
  const std::string data = encodeViewerData(grid, scene, options, stats);
  OutputFile out(path);
  uint64_t bytes = 0;
  emitPage(data, options.title, PageCancel{options.progress}, [&](std::string_view piece) {
    out.write(piece);
    bytes += piece.size();
  });
  out.commit();
  if (stats) stats->pageBytes = bytes;
}

}  // namespace vox
