#include "vox/io/info.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

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

struct Summary {
  size_t degenerate = 0;
  size_t ellipsoids = 0;
  uint64_t memoryBytes = 0;
  std::map<size_t, size_t> histogram;  // primitives per cell -> cells
};

Summary summarize(const GridFile& file) {
  Summary s;
  for (const auto& t : file.scene.triangles) s.degenerate += isDegenerate(t);
  for (const auto& sp : file.scene.spheres) s.ellipsoids += sp.isEllipsoid();
  const Grid& g = file.grid;
  s.memoryBytes = g.cellKeys.size() * 8 + g.cellStart.size() * 8 + g.primIds.size() * 4 + g.outsidePrims.size() * 4 +
                  g.solidRuns.size() * 16;
  for (size_t c = 0; c < g.occupiedCount(); ++c) ++s.histogram[g.cellStart[c + 1] - g.cellStart[c]];
  return s;
}

std::string plain(const GridFile& file) {
  const Grid& g = file.grid;
  const Scene& sc = file.scene;
  const Summary s = summarize(file);
  std::ostringstream out;
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
  out << "camera: " << (sc.camera ? (sc.camera->kind == CameraKind::Perspective ? "perspective" : "orthographic") : "none") << "\n";
  out << "occupied_cells: " << g.occupiedCount() << "\n";
  out << "solid_cells: " << g.solidCount() << "\n";
  out << "references: " << g.referenceCount() << "\n";
  out << "outside_primitives: " << g.outsidePrims.size() << "\n";
  out << "memory_bytes: " << s.memoryBytes << "\n";
  out << "primitives per occupied cell:\n";
  size_t maxCells = 1;
  for (const auto& [k, n] : s.histogram) maxCells = std::max(maxCells, n);
  for (const auto& [k, n] : s.histogram) {
    char line[64];
    std::snprintf(line, sizeof line, "  %6zu: %10zu ", k, n);
    out << line << std::string(size_t(40.0 * double(n) / double(maxCells) + 0.5), '#') << "\n";
  }
  return out.str();
}

std::string json(const GridFile& file, const InfoOptions& options) {
  const Grid& g = file.grid;
  const Scene& sc = file.scene;
  const Summary s = summarize(file);
  std::ostringstream out;
  out << "{\n";
  out << "  \"bounds\": {\"min\": " << vec(g.bounds.lo) << ", \"max\": " << vec(g.bounds.hi) << "},\n";
  out << "  \"dims\": [" << g.dims[0] << ", " << g.dims[1] << ", " << g.dims[2] << "],\n";
  out << "  \"method\": " << jsonString(methodName(g.method)) << ",\n";
  out << "  \"primitive_counts\": {\"triangle\": " << sc.triangles.size() << ", \"sphere\": " << sc.spheres.size()
      << ", \"plane\": " << sc.planes.size() << ", \"degenerate_triangle\": " << s.degenerate
      << ", \"ellipsoid\": " << s.ellipsoids << "},\n";
  out << "  \"occupied_cells\": " << g.occupiedCount() << ",\n";
  out << "  \"solid_cells\": " << g.solidCount() << ",\n";
  out << "  \"references\": " << g.referenceCount() << ",\n";
  out << "  \"outside_primitives\": " << g.outsidePrims.size() << ",\n";
  out << "  \"memory_bytes\": " << s.memoryBytes << ",\n";
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
  for (const auto& [k, n] : s.histogram) {
    out << (first ? "" : ", ") << "\"" << k << "\": " << n;
    first = false;
  }
  out << "}";
  if (options.cells) {
    out << ",\n  \"cells\": [";
    for (size_t c = 0; c < g.occupiedCount(); ++c) {
      const auto ijk = cellIndex(g.dims, g.cellKeys[c]);
      out << (c ? ",\n    " : "\n    ") << "{\"ijk\": [" << ijk[0] << ", " << ijk[1] << ", " << ijk[2] << "], \"prims\": [";
      const auto prims = g.cellPrims(c);
      for (size_t k = 0; k < prims.size(); ++k) out << (k ? ", " : "") << prims[k];
      out << "]}";
    }
    out << "\n  ]";
  }
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
  return out.str();
}

}  // namespace

std::string formatGridInfo(const GridFile& file, const InfoOptions& options) {
  return options.json ? json(file, options) : plain(file);
}

}  // namespace vox
