// vox-export speed: the 69k-triangle Stanford bunny voxelized at 512^3 (exact method), exported in each face mode.
// BM_BuildVoxelMesh times the mesh construction alone; BM_ExportPly adds the binary PLY writer (what vox-export
// does after reading the grid). Counters: voxels, vertices, faces, bytes written. Run with --benchmark_filter=...;
// the grid is built once, on first use.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "vox/import/import.h"
#include "vox/export/voxel_mesh.h"
#include "vox/voxelize/voxelize.h"

namespace {

struct BunnyGrid {
  vox::Scene scene;
  vox::Grid grid;
};

const BunnyGrid& bunny() {
  static const BunnyGrid data = [] {
    BunnyGrid d;
    d.scene = vox::importPly(VOX_SEED_DIR "/meshes/bun_zipper.ply");
    vox::VoxelizeOptions options;
    options.dims = vox::dimsForResolution(*vox::sceneBounds(d.scene), 512);
    d.grid = vox::voxelizeScene(d.scene, options);
    return d;
  }();
  return data;
}

const vox::FaceMode kModes[] = {vox::FaceMode::All, vox::FaceMode::Exposed, vox::FaceMode::Merged};

void BM_BuildVoxelMesh(benchmark::State& state) {
  const BunnyGrid& b = bunny();
  const vox::FaceMode mode = kModes[state.range(0)];
  const vox::ColorMode color = state.range(1) ? vox::ColorMode::Count : vox::ColorMode::None;
  vox::VoxelMeshStats stats;
  size_t faces = 0, vertices = 0;
  for (auto _ : state) {
    const vox::VoxelMesh mesh = vox::buildVoxelMesh(b.grid, b.scene, mode, color, &stats);
    faces = mesh.faceCount();
    vertices = mesh.vertexCount();
    benchmark::DoNotOptimize(mesh.positions.data());
  }
  state.SetLabel(vox::faceModeName(mode) + (state.range(1) ? "/count" : "/none"));
  state.counters["voxels"] = double(stats.voxels);
  state.counters["vertices"] = double(vertices);
  state.counters["faces"] = double(faces);
}

void BM_ExportPly(benchmark::State& state) {
  const BunnyGrid& b = bunny();
  const vox::FaceMode mode = kModes[state.range(0)];
  const std::string path = (std::filesystem::temp_directory_path() / "vox_bench_export.ply").string();
  size_t faces = 0;
  for (auto _ : state) {
    const vox::VoxelMesh mesh = vox::buildVoxelMesh(b.grid, b.scene, mode, vox::ColorMode::Count);
    vox::writeVoxelMesh(path, mesh, true);
    faces = mesh.faceCount();
  }
  state.SetLabel(vox::faceModeName(mode) + "/count/binary-ply");
  state.counters["faces"] = double(faces);
  state.counters["bytes"] = double(std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

}  // namespace

BENCHMARK(BM_BuildVoxelMesh)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ExportPly)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
