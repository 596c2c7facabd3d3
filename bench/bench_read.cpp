// Reading meshes: vox::loadScene (our exact double reader, issue 26's "200 MB/s per thread") against OpenMesh's
// OBJ and PLY readers (floats) on the same files, runs alternating, the best of --runs each; MB/s and the ratio.
//   build/bench/bench_read [--runs N] [FILE...]     (default: the SheenCloth OBJ, the 69k bunny OBJ and PLY)
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "vox/import/import.h"

namespace {

using Clock = std::chrono::steady_clock;
using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;

double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

double timeOurs(const std::string& path, size_t& triangles) {
  const auto start = Clock::now();
  const vox::Scene scene = vox::loadScene(path);
  const double s = seconds(start);
  triangles = scene.triangles.size();
  return s;
}

double timeOpenMesh(const std::string& path, size_t& faces) {
  const auto start = Clock::now();
  OpenMeshTriangles mesh;
  if (!OpenMesh::IO::read_mesh(mesh, path)) return -1;
  const double s = seconds(start);
  faces = mesh.n_faces();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 7;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc)
      runs = std::max(1, std::atoi(argv[++i]));
    else
      files.push_back(a);
  }
  if (files.empty()) {
    const std::string seed = VOX_SEED_DIR;
    files = {seed + "/meshes/derived/sheencloth_115k.obj", seed + "/meshes/derived/stanford_bunny_69k.obj",
             seed + "/meshes/bun_zipper.ply"};
  }
  std::printf("%-26s %9s %10s %10s %10s %10s %8s\n", "file", "MB", "ours_ms", "ours_MB/s", "omesh_ms", "omesh_MB/s",
              "ratio");
  for (const std::string& f : files) {
    const double mb = double(std::filesystem::file_size(f)) / 1e6;
    double ours = 1e30, theirs = 1e30;
    size_t ourTriangles = 0, theirFaces = 0;
    for (int r = 0; r < runs; ++r) {  // alternating, so that a noisy moment hits both
      ours = std::min(ours, timeOurs(f, ourTriangles));
      const double t = timeOpenMesh(f, theirFaces);
      if (t >= 0) theirs = std::min(theirs, t);
    }
    std::printf("%-26s %9.2f %10.2f %10.0f %10.2f %10.0f %8.2f   (%zu triangles; OpenMesh %zu faces)\n",
                std::filesystem::path(f).filename().c_str(), mb, ours * 1e3, mb / ours, theirs * 1e3, mb / theirs,
                theirs / ours, ourTriangles, theirFaces);
  }
  return 0;
}
