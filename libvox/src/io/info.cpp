#include "vox/io/info.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <functional>
#include <sstream>

#include "vox/core/compensated_sum.h"
#include "vox/core/power_of_two_frame.h"
#include "vox/io/grid_set.h"

namespace vox {

namespace {

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string vec(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v.x, v.y, v.z);
  return buf;
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (uint8_t(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Counts over the cells, added up block by block (a whole grid, or a set's layers of bricks in key order).
struct CellTotals {
  uint64_t occupied = 0, references = 0, solidCells = 0, solidRuns = 0;
  std::map<size_t, size_t> histogram;  // primitives per cell -> cells
  CellRun lastRun;

  void add(const Grid& g) {
    occupied += g.occupiedCount();
    references += g.referenceCount();
    for (size_t c = 0; c < g.occupiedCount(); ++c) ++histogram[g.cellStart[c + 1] - g.cellStart[c]];
    // A set's layers each merge their runs; a run touching the previous layer's last is one run of the grid.
    for (const CellRun& r : g.solidRuns) {
      solidCells += r.count;
      if (solidRuns > 0 && lastRun.first + lastRun.count == r.first) {
        lastRun.count += r.count;
      } else {
        ++solidRuns;
        lastRun = r;
      }
    }
  }
};

struct Summary {
  size_t degenerate = 0;
  size_t ellipsoids = 0;
  uint64_t memoryBytes = 0;
};

// What vox-info says about a grid: its scene, its plan (bounds, dims, method, outsidePrims) and its cells' totals.
struct InfoSource {
  const Scene& scene;
  const Grid& plan;
  const CellTotals& totals;
};

Summary summarize(const InfoSource& in) {
  Summary s;
  for (const auto& t : in.scene.triangles) s.degenerate += isDegenerate(t);
  for (const auto& sp : in.scene.spheres) s.ellipsoids += sp.isEllipsoid();
  const CellTotals& c = in.totals;
  s.memoryBytes =
      c.occupied * 8 + (c.occupied + 1) * 8 + c.references * 4 + in.plan.outsidePrims.size() * 4 + c.solidRuns * 16;
  return s;
}

// The solid's volume as the scene gives it: the triangles' signed volume (divergence theorem: sum of a . (b x c) / 6,
// positive for outward-oriented closed meshes) plus each sphere's and ellipsoid's 4/3 pi r^3 |det L|.
// `meshVolume` gets the triangles' part alone: negative when they face inward (the fill and the fractions go by the
// winding number's magnitude, so they count what such a mesh encloses as solid).
double sceneVolume(const Scene& sc, double* meshVolume = nullptr) {
  CompensatedSum v;
  for (const Triangle& t : sc.triangles) v.add(dot(t.v[0], cross(t.v[1], t.v[2])) / 6);
  if (meshVolume) *meshVolume = v.value();
  for (const Sphere& sp : sc.spheres)
    v.add(4.0 / 3.0 * M_PI * sp.radius * sp.radius * sp.radius * std::fabs(linearDeterminant(sp.transform)));
  return v.value();
}

// What --sdf and --fraction stored: the band's size and range; the fractions' volume beside the scene's own, in
// world units and in cells. The cells' figures are computed in the power-of-two frame of the scene and the bounds
// (vox/core/power_of_two_frame.h), so they stay finite where a world volume does not fit a double (a cube of side
// 1e150 has a volume of 1e450).
struct DistanceSummary {
  double bandMin = 0, bandMax = 0;
  double fractionVolume = 0, sceneVolume = 0;
  double meshVolume = 0;  // the triangles' signed volume: negative when they face inward
  double fractionCells = 0, sceneCells = 0;
  bool worldFits() const { return std::isfinite(fractionVolume) && std::isfinite(sceneVolume); }
};

DistanceSummary summarizeDistances(const Scene& sc, const Grid& g, uint64_t solidCells) {
  DistanceSummary d;
  if (!g.sdfValues.empty()) {
    d.bandMin = *std::min_element(g.sdfValues.begin(), g.sdfValues.end());
    d.bandMax = *std::max_element(g.sdfValues.begin(), g.sdfValues.end());
  }
  if (!g.fractions.empty()) {
    const PowerOfTwoFrame frame = fractionFrame(sc, g.bounds);
    const Box framed = frame.toFrame(g.bounds);
    double cell = 1, framedCell = 1;
    for (int a = 0; a < 3; ++a) {
      cell *= (g.bounds.hi[a] - g.bounds.lo[a]) / g.dims[a];
      framedCell *= (framed.hi[a] - framed.lo[a]) / g.dims[a];
    }
    CompensatedSum sum;
    sum.add(double(solidCells));
    for (double f : g.fractions) sum.add(f);
    d.fractionCells = sum.value();
    d.fractionVolume = d.fractionCells * cell;
    d.sceneVolume = sceneVolume(sc, &d.meshVolume);
    d.sceneCells = sceneVolume(sceneInFrame(sc, frame)) / framedCell;
  }
  return d;
}

void plainDistances(std::ostream& out, const InfoSource& in) {
  const Grid& g = in.plan;
  const DistanceSummary d = summarizeDistances(in.scene, g, in.totals.solidCells);
  if (g.sdfHalfWidth > 0)
    out << "distance_band: " << g.sdfKeys.size() << " cells within " << num(g.sdfHalfWidth)
        << " cell widths, signed distances " << num(d.bandMin) << " to " << num(d.bandMax) << "\n";
  if (!g.fractions.empty()) {
    if (d.worldFits())
      out << "fraction_volume: " << num(d.fractionVolume) << " (the scene's own volume: " << num(d.sceneVolume);
    else
      out << "fraction_volume: " << num(d.fractionCells) << " cells (the scene's own volume: " << num(d.sceneCells)
          << " cells; in world units these volumes are beyond a double";
    out << (d.meshVolume < 0
                ? "; its triangles face inward, and the fractions count the solid they enclose all the same"
                : std::string())
        << ")\n";
  }
}

void jsonDistances(std::ostream& out, const InfoSource& in) {
  const Grid& g = in.plan;
  const DistanceSummary d = summarizeDistances(in.scene, g, in.totals.solidCells);
  if (g.sdfHalfWidth > 0)
    out << "  \"distance_band\": {\"cells\": " << g.sdfKeys.size() << ", \"half_width\": " << num(g.sdfHalfWidth)
        << ", \"min\": " << num(d.bandMin) << ", \"max\": " << num(d.bandMax) << "},\n";
  if (!g.fractions.empty())
    out << "  \"fractions\": {\"volume\": " << (d.worldFits() ? num(d.fractionVolume) : "null")
        << ", \"scene_volume\": " << (d.worldFits() ? num(d.sceneVolume) : "null")
        << ", \"volume_cells\": " << num(d.fractionCells) << ", \"scene_volume_cells\": " << num(d.sceneCells)
        << ", \"mesh_faces_inward\": " << (d.meshVolume < 0 ? "true" : "false") << "},\n";
}

void plain(std::ostream& out, const InfoSource& in) {
  const Grid& g = in.plan;
  const Scene& sc = in.scene;
  const CellTotals& t = in.totals;
  const Summary s = summarize(in);
  out << "bounds: " << vec(g.bounds.lo) << " - " << vec(g.bounds.hi) << "\n";
  out << "dims: " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << " (" << g.cellCount() << " cells)\n";
  out << "method: " << methodName(g.method) << "\n";
  out << "triangles: " << sc.triangles.size() << " (" << s.degenerate << " degenerate)\n";
  out << "spheres: " << sc.spheres.size() << " (" << s.ellipsoids << " ellipsoids)\n";
  out << "planes: " << sc.planes.size() << "\n";
  out << "materials: " << sc.materials.size() << "\n";
  out << "solid_textures: " << sc.solidTextures.size();
  for (SolidKind k : {SolidKind::Checkerboard, SolidKind::Noise, SolidKind::Marble, SolidKind::Wood}) {
    const auto n = std::count_if(sc.solidTextures.begin(), sc.solidTextures.end(),
                                 [&](const SolidTexture& t) { return t.kind == k; });
    if (n > 0) out << " " << solidKindName(k) << ":" << n;
  }
  out << "\n";
  out << "lights: " << sc.lights.size() << "\n";
  out << "camera: "
      << (sc.camera ? (sc.camera->kind == CameraKind::Perspective ? "perspective" : "orthographic") : "none");
  // Which side its angle or size spans decides the framing of a non-square image (docs/trace.md).
  if (sc.camera)
    out << (sc.camera->span == CameraSpan::LongerSide ? " (spans the longer side)" : " (spans the height)");
  out << "\n";
  out << "occupied_cells: " << t.occupied << "\n";
  out << "solid_cells: " << t.solidCells << "\n";
  out << "references: " << t.references << "\n";
  out << "outside_primitives: " << g.outsidePrims.size() << "\n";
  out << "memory_bytes: " << s.memoryBytes << "\n";
  plainDistances(out, in);
  out << "primitives per occupied cell:\n";
  size_t maxCells = 1;
  for (const auto& [k, n] : t.histogram) maxCells = std::max(maxCells, n);
  for (const auto& [k, n] : t.histogram) {
    char line[64];
    std::snprintf(line, sizeof line, "  %6zu: %10zu ", k, n);
    out << line << std::string(size_t(40.0 * double(n) / double(maxCells) + 0.5), '#') << "\n";
  }
}

// Everything before the cells.
void jsonHead(std::ostream& out, const InfoSource& in) {
  const Grid& g = in.plan;
  const Scene& sc = in.scene;
  const CellTotals& t = in.totals;
  const Summary s = summarize(in);
  out << "{\n";
  out << "  \"bounds\": {\"min\": " << vec(g.bounds.lo) << ", \"max\": " << vec(g.bounds.hi) << "},\n";
  out << "  \"dims\": [" << g.dims[0] << ", " << g.dims[1] << ", " << g.dims[2] << "],\n";
  out << "  \"method\": " << jsonString(methodName(g.method)) << ",\n";
  out << "  \"primitive_counts\": {\"triangle\": " << sc.triangles.size() << ", \"sphere\": " << sc.spheres.size()
      << ", \"plane\": " << sc.planes.size() << ", \"degenerate_triangle\": " << s.degenerate
      << ", \"ellipsoid\": " << s.ellipsoids << "},\n";
  out << "  \"occupied_cells\": " << t.occupied << ",\n";
  out << "  \"solid_cells\": " << t.solidCells << ",\n";
  out << "  \"references\": " << t.references << ",\n";
  out << "  \"outside_primitives\": " << g.outsidePrims.size() << ",\n";
  out << "  \"memory_bytes\": " << s.memoryBytes << ",\n";
  jsonDistances(out, in);
  // Solid textures by the material that uses them (the course's Checkerboard, Noise, Marble, Wood).
  out << "  \"solid_textures\": [";
  for (size_t m = 0, n = 0; m < sc.materials.size(); ++m) {
    if (sc.materials[m].solidTexture == kNoSolidTexture) continue;
    const SolidTexture& t = sc.solidTextures[sc.materials[m].solidTexture];
    out << (n++ ? ", " : "") << "{\"material\": " << m << ", \"kind\": " << jsonString(solidKindName(t.kind))
        << ", \"materials\": [" << t.materials[0] << ", " << t.materials[1] << "], \"octaves\": " << t.octaves
        << ", \"frequency\": " << num(t.frequency) << ", \"amplitude\": " << num(t.amplitude) << "}";
  }
  out << "],\n";
  out << "  \"histogram\": {";
  bool first = true;
  for (const auto& [k, n] : t.histogram) {
    out << (first ? "" : ", ") << "\"" << k << "\": " << n;
    first = false;
  }
  out << "}";
}

// The cells of one block (in key order after the previous block's); `first`: no cell written yet.
void jsonCells(std::ostream& out, const Grid& g, bool& first) {
  std::string line;
  for (size_t c = 0; c < g.occupiedCount(); ++c) {
    const auto ijk = cellIndex(g.dims, g.cellKeys[c]);
    line.assign(first ? "\n    " : ",\n    ");
    first = false;
    line += "{\"ijk\": [" + std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]) + ", " + std::to_string(ijk[2]) +
            "], \"prims\": [";
    const auto prims = g.cellPrims(c);
    for (size_t k = 0; k < prims.size(); ++k) (line += k ? ", " : "") += std::to_string(prims[k]);
    line += "]}";
    out << line;
  }
}

void jsonTail(std::ostream& out, const Scene& sc, const InfoOptions& options) {
  if (options.primitives) {
    out << ",\n  \"primitives\": [";
    size_t id = 0;
    auto sep = [&] { return id == 0 ? "\n    " : ",\n    "; };
    for (const auto& t : sc.triangles) {
      out << sep() << "{\"id\": " << id << ", \"type\": \"triangle\", \"v\": [" << vec(t.v[0]) << ", " << vec(t.v[1])
          << ", " << vec(t.v[2]) << "], \"material\": " << t.material << "}";
      ++id;
    }
    for (const auto& sp : sc.spheres) {
      out << sep() << "{\"id\": " << id << ", \"type\": \"sphere\", \"center\": " << vec(sp.center)
          << ", \"radius\": " << num(sp.radius);
      if (sp.isEllipsoid()) {
        out << ", \"transform\": [";
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c) out << (r || c ? ", " : "") << num(sp.transform.m[r][c]);
        out << "]";
      }
      out << ", \"material\": " << sp.material << "}";
      ++id;
    }
    for (const auto& p : sc.planes) {
      out << sep() << "{\"id\": " << id << ", \"type\": \"plane\", \"normal\": " << vec(p.normal)
          << ", \"offset\": " << num(p.offset) << ", \"material\": " << p.material << "}";
      ++id;
    }
    out << "\n  ]";
  }
  out << "\n}\n";
}

// The whole report; `forEachBlock(visit, ordered)` hands the cells over (in key order when `ordered`: the totals
// need no order), once for the totals and once more for --cells.
using BlockSource = std::function<void(const std::function<void(const Grid&)>&, bool ordered)>;
void writeInfo(std::ostream& out, const Scene& scene, const Grid& plan, const InfoOptions& options,
               const BlockSource& forEachBlock) {
  CellTotals totals;
  forEachBlock([&](const Grid& block) { totals.add(block); }, false);
  const InfoSource in{scene, plan, totals};
  if (!options.json) return plain(out, in);
  jsonHead(out, in);
  if (options.cells) {
    out << ",\n  \"cells\": [";
    bool first = true;
    forEachBlock([&](const Grid& block) { jsonCells(out, block, first); }, true);
    out << "\n  ]";
  }
  jsonTail(out, scene, options);
}

}  // namespace

void writeGridInfo(std::ostream& out, const GridFile& file, const InfoOptions& options) {
  writeInfo(out, file.scene, file.grid, options, [&](const auto& visit, bool) { visit(file.grid); });
}

void writeGridSetInfo(std::ostream& out, const std::string& setPath, const InfoOptions& options) {
  const GridSetManifest m = readGridSetManifest(setPath);
  const GridFile sceneFile = readGridSetScene(setPath, m);
  writeInfo(out, sceneFile.scene, sceneFile.grid, options, [&](const auto& visit, bool ordered) {
    forEachGridSetLayer(setPath, m, sceneFile, visit, ordered ? LayerCells::Sorted : LayerCells::BrickOrder);
  });
}

std::string formatGridInfo(const GridFile& file, const InfoOptions& options) {
  std::ostringstream out;
  writeGridInfo(out, file, options);
  return out.str();
}

}  // namespace vox
