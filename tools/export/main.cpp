// vox-export: grid file -> voxel mesh (.ply .obj .off .stl .glb .gltf).
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <new>
#include <stdexcept>

#include "../common/cli.h"
#include "vox/io/atomic_file.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/core/progress.h"
#include "vox/export/voxel_mesh.h"
#include "vox/export/voxel_format.h"
#include "vox/export/viewer_page.h"

namespace {

struct Options {
  std::string grid;
  std::string output;
  std::string faces = "exposed";
  std::string color = "count";
  bool ascii = false;
  bool stats = false;
  vox::cli::CommonOptions common;
};

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Runs an export step on a grid that has been read: the writers and mesh builders see a grid in memory and a stream,
// so their messages ("vox: ... voxels need ...", "grid: cell key ...") name no file; here each gets the grid's name
// in front, as every read error has (a message that already names it, such as a set's, is kept). Output errors name
// the output already. An allocation that failed anyway (std::bad_alloc, or std::length_error from a size beyond
// what a vector can hold) becomes the same kind of message, exit 2 as a LimitError.
template <typename F>
auto namingGrid(const Options& opt, F&& step) -> decltype(step()) {
  using namespace vox;
  const auto named = [&](const char* what) {
    const std::string message = what;
    return message.find(opt.grid) != std::string::npos ? message : opt.grid + ": " + message;
  };
  try {
    return step();
  } catch (const OutputError&) {
    throw;
  } catch (const UsageError&) {
    throw;
  } catch (const LimitError& e) {
    throw LimitError(named(e.what()));
  } catch (const Error& e) {
    throw InputError(named(e.what()));
  } catch (const std::bad_alloc&) {
    fail<LimitError>(opt.grid, ": ", opt.output,
                     ": out of memory (the export needed more than estimated; try a smaller grid)");
  } catch (const std::length_error& e) {
    fail<LimitError>(opt.grid, ": ", opt.output, ": a size beyond what memory can hold (", e.what(), ")");
  }
}

// Voxel formats (.binvox, .vox, .vdb): the cells themselves, not a mesh; --faces and --ascii do not apply.
int runVoxelFormat(const Options& opt, vox::VoxelFormat format) {
  using namespace vox;
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  checkOutputPath(opt.output, {opt.grid});
  const ColorMode color = parseColorMode(opt.color);
  ProgressBar bar("exporting", opt.common.quiet);
  // binvox and .vox need only the voxels in key order (with each occupied cell's colour for .vox): a set is then
  // read one layer of bricks at a time on each of the writer's passes instead of assembled, which keeps the peak
  // memory to a layer (docs/scaling.md). .vdb builds OpenVDB's tree of the whole grid, so its set is assembled.
  const bool layered = format != VoxelFormat::Vdb && isGridSet(opt.grid);
  GridSetManifest set;
  GridFile file;
  if (layered) {
    set = readGridSetManifest(opt.grid);
    file = readGridSetScene(opt.grid, set);
  } else {
    file = readGridOrSet(opt.grid);
  }
  uint64_t occupied = file.grid.occupiedCount(), solid = file.grid.solidCount();
  for (const BrickEntry& e : set.entries) {
    occupied += e.occupied;
    solid += e.solid;
  }
  bar.update(0.1);
  std::vector<Rgb8> colors;
  if (!layered && format == VoxelFormat::MagicaVoxel && color != ColorMode::None)
    colors = namingGrid(opt, [&] { return occupiedCellColors(file.grid, file.scene, color); });
  bar.update(0.2);
  const auto writeStart = std::chrono::steady_clock::now();
  const auto progress = [&](double f) { bar.update(0.2 + 0.8 * f); };
  const VoxelFileReport report = namingGrid(opt, [&] {
    return layered ? writeGridSetVoxelFile(opt.output, format, opt.grid, set, file, color, progress)
                   : writeVoxelFile(opt.output, format, file.grid, colors, progress);
  });
  const double writeSeconds = secondsSince(writeStart);
  bar.finish();
  if (format == VoxelFormat::Binvox && report.binvoxShiftVoxels > 1e-9 && !opt.common.quiet)
    std::fprintf(stderr,
                 "vox-export: warning: %s: binvox voxels are cubes; the grid's cells are not, so they are written as "
                 "cubes of side %.9g (the longest axis' cell) and the grid's far face moves by up to %.3g voxels\n",
                 opt.output.c_str(), report.binvoxVoxelSide, report.binvoxShiftVoxels);
  if (report.paletteReduced && !opt.common.quiet)
    std::fprintf(stderr, "vox-export: warning: %s: %u voxel colours reduced to a palette of %u (median cut)\n",
                 opt.output.c_str(), report.gridColors, report.paletteColors);
  if (opt.stats) {
    std::error_code sizeError;
    const auto bytes = std::filesystem::file_size(opt.output, sizeError);
    std::fprintf(stderr,
                 "voxels: %llu\noccupied_cells: %zu\nsolid_cells: %llu\n%s: %llu\ncolors: %u\n"
                 "palette_colors: %u\noutput_bytes: %llu\nwrite_seconds: %.6f\ntotal_seconds: %.6f\n",
                 (unsigned long long)report.voxels, size_t(occupied), (unsigned long long)solid,
                 format == VoxelFormat::Vdb ? "vdb_leaf_nodes" : "models", (unsigned long long)report.models,
                 report.gridColors, report.paletteColors, (unsigned long long)(sizeError ? 0 : bytes), writeSeconds,
                 secondsSince(start));
  }
  return kExitOk;
}

// The viewer page (.html, vox/export/viewer_page.h): the merged surface, the cells and the scene's primitives in one
// self-contained page; --faces and --ascii do not apply (the page always draws the merged surface).
bool isViewerPagePath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".html" || ext == ".htm";
}

int runViewerPage(const Options& opt) {
  using namespace vox;
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  if (!viewerPageAvailable()) viewerPageHtml({}, {});  // the build's UsageError, before reading a large grid
  checkOutputPath(opt.output, {opt.grid});
  ViewerPageOptions page;
  page.color = parseColorMode(opt.color);
  page.title = std::filesystem::path(opt.grid).filename().string();
  ProgressBar bar("exporting", opt.common.quiet);
  const GridFile file = readGridOrSet(opt.grid);
  bar.update(0.3);
  ViewerDataStats stats;
  namingGrid(opt, [&] { writeViewerPage(opt.output, file.grid, file.scene, page, &stats); });
  bar.finish();
  if (opt.stats)
    std::fprintf(stderr,
                 "voxels: %llu\nsurface_vertices: %llu\nsurface_triangles: %llu\nstored_ids: %llu\ndata_bytes: %llu\n"
                 "output_bytes: %llu\ntotal_seconds: %.6f\n",
                 (unsigned long long)stats.voxels, (unsigned long long)stats.surfaceVertices,
                 (unsigned long long)stats.surfaceTriangles, (unsigned long long)stats.storedIds,
                 (unsigned long long)stats.dataBytes, (unsigned long long)stats.pageBytes, secondsSince(start));
  return kExitOk;
}

int run(const Options& opt) {
  using namespace vox;
  if (const auto format = voxelFormatFromPath(opt.output)) return runVoxelFormat(opt, *format);
  if (isViewerPagePath(opt.output)) return runViewerPage(opt);
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  // Refuse a bad output before reading a large grid.
  try {
    meshFormatFromPath(opt.output);
  } catch (const InputError& e) {
    throw UsageError(e.what());
  }
  checkOutputPath(opt.output, {opt.grid});
  // An OBJ writes its materials to NAME.mtl beside it: that second output must not be the grid either.
  if (meshFormatFromPath(opt.output) == MeshFormat::Obj)
    checkOutputPath(std::filesystem::path(opt.output).replace_extension(".mtl").string(), {opt.grid});
  const FaceMode faces = parseFaceMode(opt.faces);
  const ColorMode color = parseColorMode(opt.color);

  ProgressBar bar("exporting", opt.common.quiet);
  const GridFile file = readGridOrSet(opt.grid);
  bar.update(0.2);
  VoxelMeshStats stats;
  const auto buildStart = std::chrono::steady_clock::now();
  const VoxelMesh mesh = namingGrid(opt, [&] { return buildVoxelMesh(file.grid, file.scene, faces, color, &stats); });
  const double buildSeconds = secondsSince(buildStart);
  bar.update(0.6);
  const auto writeStart = std::chrono::steady_clock::now();
  namingGrid(opt, [&] { writeVoxelMesh(opt.output, mesh, !opt.ascii); });
  const double writeSeconds = secondsSince(writeStart);
  bar.finish();

  if (opt.stats) {
    // The reduction needs both face counts: build the merged surface when it was not the one asked for.
    size_t exposedFaces = stats.exposedFaces, mergedFaces = mesh.faceCount();
    if (faces != FaceMode::Merged) {
      VoxelMeshStats mergedStats;
      mergedFaces = namingGrid(opt, [&] {
        return buildVoxelMesh(file.grid, file.scene, FaceMode::Merged, color, &mergedStats).faceCount();
      });
      exposedFaces = mergedStats.exposedFaces;
    }
    std::error_code sizeError;
    const auto bytes = std::filesystem::file_size(opt.output, sizeError);
    std::fprintf(stderr,
                 "voxels: %zu\nfaces_mode: %s\ncolor_mode: %s\nvertices: %zu\nfaces: %zu\nexposed_faces: %zu\n"
                 "merged_faces: %zu\nmerged_over_exposed: %.4f\noutput_bytes: %llu\nbuild_seconds: %.6f\n"
                 "write_seconds: %.6f\ntotal_seconds: %.6f\n",
                 stats.voxels, faceModeName(faces).c_str(), colorModeName(color).c_str(), mesh.vertexCount(),
                 mesh.faceCount(), exposedFaces, mergedFaces,
                 exposedFaces ? double(mergedFaces) / double(exposedFaces) : 1.0,
                 (unsigned long long)(sizeError ? 0 : bytes), buildSeconds, writeSeconds, secondsSince(start));
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  CLI::App app{
      "Write the voxels of a grid file (occupied and solid cells) as a mesh for MeshLab, Blender and "
      "other mesh tools; the format follows the output's extension.",
      "vox-export"};
  app.add_option("grid", opt.grid, "Input grid file (.vgrid)")->required();
  app.add_option("-o,--output", opt.output,
                 "Output mesh: .ply (binary unless --ascii, face colours), .obj (vertex colours), .off (face "
                 "colours), .stl (binary unless --ascii, no colours), .glb/.gltf (vertex colours); voxels: .binvox "
                 "(binvox, cubic voxels), .vox (MagicaVoxel, palette from --color), .vdb (OpenVDB grids density and "
                 "count); .html: an interactive viewer page (three.js inside, opens from disk, no network)")
      ->required();
  app.add_option("--faces", opt.faces,
                 "all: a closed cube of 12 triangles per voxel; exposed (default): the quads between voxels and "
                 "empty cells, vertices shared, closed and 2-manifold; merged: the exposed quads merged into "
                 "rectangles of one colour, still closed, 2-manifold and free of T-junctions (STL and glTF get "
                 "triangles)")
      ->check(CLI::IsMember({"all", "exposed", "merged"}));
  app.add_option("--color", opt.color,
                 "count (default): primitives per cell on the viridis ramp of vox-trace --mode voxels (log scale, 1 "
                 "to the grid's maximum); material: the diffuse colour of the material held by the majority of the "
                 "cell's primitives (ties: lowest material index); none. Solid cells are grey.")
      ->check(CLI::IsMember({"count", "material", "none"}));
  app.add_flag("--ascii", opt.ascii, "Write ASCII PLY or STL instead of binary");
  app.add_flag("--stats", opt.stats,
               "Print statistics (name: value) on stderr: voxels, vertices, faces, exposed and merged face counts "
               "and their ratio, times");
  vox::cli::addCommonOptions(app, opt.common);
  app.footer("Exit codes: 0 ok, 1 usage (including an unknown output extension), 2 bad input, 3 cannot write.");
  if (auto code = vox::cli::parse(app, argc, argv)) return *code;
  return vox::runTool("vox-export", [&] { return run(opt); });
}
