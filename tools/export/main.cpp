// vox-export: grid file -> voxel mesh (.ply .obj .off .stl .glb .gltf).
#include <unistd.h>

#include <chrono>
#include <filesystem>

#include "../common/cli.h"
#include "vox/io/atomic_file.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"
#include "vox/core/progress.h"
#include "vox/export/voxel_mesh.h"

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

int run(const Options& opt) {
  using namespace vox;
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
  const GridFile file = readGridFile(opt.grid);
  bar.update(0.2);
  VoxelMeshStats stats;
  const auto buildStart = std::chrono::steady_clock::now();
  const VoxelMesh mesh = buildVoxelMesh(file.grid, file.scene, faces, color, &stats);
  const double buildSeconds = secondsSince(buildStart);
  bar.update(0.6);
  const auto writeStart = std::chrono::steady_clock::now();
  writeVoxelMesh(opt.output, mesh, !opt.ascii);
  const double writeSeconds = secondsSince(writeStart);
  bar.finish();

  if (opt.stats) {
    // The reduction needs both face counts: build the merged surface when it was not the one asked for.
    size_t exposedFaces = stats.exposedFaces, mergedFaces = mesh.faceCount();
    if (faces != FaceMode::Merged) {
      VoxelMeshStats mergedStats;
      mergedFaces = buildVoxelMesh(file.grid, file.scene, FaceMode::Merged, color, &mergedStats).faceCount();
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
  CLI::App app{"Write the voxels of a grid file (occupied and solid cells) as a mesh for MeshLab, Blender and "
               "other mesh tools; the format follows the output's extension.",
               "vox-export"};
  app.add_option("grid", opt.grid, "Input grid file (.vgrid)")->required();
  app.add_option("-o,--output", opt.output,
                 "Output mesh: .ply (binary unless --ascii, face colours), .obj (vertex colours), .off (face "
                 "colours), .stl (binary unless --ascii, no colours), .glb/.gltf (vertex colours)")
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
