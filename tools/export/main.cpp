// vox-export: grid file -> voxel mesh (.ply .obj .off .stl .glb .gltf), voxel file (run_voxel_format.cpp) or viewer
// page (run_viewer_page.cpp).
#include <chrono>
#include <filesystem>

#include "options.h"
#include "runs.h"
#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/export/level_surface.h"
#include "vox/export/voxel_mesh.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"

namespace {

using namespace vox;
using export_tool::namingGrid;
using export_tool::Options;
using export_tool::secondsSince;

// --surface: the level set of the grid's distances as a triangle mesh (vox/export/level_surface.h).
int runSurface(const Options& opt) {
  const auto start = std::chrono::steady_clock::now();
  ProgressBar bar("surface", opt.common.quiet);
  const GridFile file = readGridOrSet(opt.grid);
  bar.update(0.2);
  LevelSurfaceStats stats;
  const VoxelMesh mesh = namingGrid(opt, [&] { return extractLevelSurface(file.grid, *opt.surface, &stats); });
  bar.update(0.6);
  const auto writeStart = std::chrono::steady_clock::now();
  namingGrid(opt, [&] { writeVoxelMesh(opt.output, mesh, !opt.ascii); });
  const double writeSeconds = secondsSince(writeStart);
  bar.finish();
  if (opt.stats)
    std::fprintf(stderr,
                 "surface_level: %.17g\nvertices: %zu\nfaces: %zu\ncubes: %zu\ncap_faces: %zu\nbuild_seconds: %.6f\n"
                 "write_seconds: %.6f\ntotal_seconds: %.6f\n",
                 *opt.surface, mesh.vertexCount(), mesh.faceCount(), stats.cubes, stats.capTriangles, stats.seconds,
                 writeSeconds, secondsSince(start));
  return kExitOk;
}

int run(const Options& opt) {
  if (opt.surface && (voxelFormatFromPath(opt.output) || export_tool::isViewerPagePath(opt.output)))
    throw UsageError("--surface writes a mesh: .ply, .obj, .off, .stl, .glb or .gltf, not " + opt.output);
  if (const auto format = voxelFormatFromPath(opt.output)) return export_tool::runVoxelFormat(opt, *format);
  if (export_tool::isViewerPagePath(opt.output)) return export_tool::runViewerPage(opt);
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
  if (opt.surface) return runSurface(opt);
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
  if (auto code = export_tool::parseCommandLine(argc, argv, opt)) return *code;
  return runTool("vox-export", [&] { return run(opt); });
}
