// Reading meshes: vox::loadScene (our exact double reader, issue 26's "200 MB/s per thread") on one thread and on
// all, against OpenMesh's OBJ and PLY readers (floats, one thread) on the same files; runs alternating, the best of
// --runs each; MB/s and the ratio of OpenMesh's time to ours on all threads.
//   build/bench/bench_read [--runs N] [--ours-only] [FILE...]   (default: the SheenCloth OBJ, the 69k bunny OBJ, PLY)
// --ours-only leaves OpenMesh out, for a profile of our reader alone (perf record).
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <tbb/global_control.h>
#include <tbb/info.h>

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

double timeOurs(const std::string& path, size_t& triangles, int threads) {
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
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
  bool oursOnly = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--ours-only")
      oursOnly = true;
    else if (a == "--runs" && i + 1 < argc)
      runs = std::max(1, std::atoi(argv[++i]));
    else
      files.push_back(a);
  }
  if (files.empty()) {
    const std::string seed = VOX_SEED_DIR;
    files = {seed + "/meshes/derived/sheencloth_115k.obj", seed + "/meshes/derived/stanford_bunny_69k.obj",
             seed + "/meshes/bun_zipper.ply"};
  }
  const int threads = tbb::info::default_concurrency();
  std::printf("%-26s %7s %9s %9s %9s %9s %9s %10s %7s  (%d threads)\n", "file", "MB", "1t_ms", "1t_MB/s", "all_ms",
              "all_MB/s", "omesh_ms", "omesh_MB/s", "ratio", threads);
  for (const std::string& f : files) {
    const double mb = double(std::filesystem::file_size(f)) / 1e6;
    double one = 1e30, all = 1e30, theirs = 1e30;
    size_t ourTriangles = 0, theirFaces = 0;
    for (int r = 0; r < runs; ++r) {  // alternating, so that a noisy moment hits all three
      one = std::min(one, timeOurs(f, ourTriangles, 1));
      all = std::min(all, timeOurs(f, ourTriangles, threads));
      const double t = oursOnly ? -1 : timeOpenMesh(f, theirFaces);
      if (t >= 0) theirs = std::min(theirs, t);
    }
    std::printf("%-26s %7.2f %9.2f %9.0f %9.2f %9.0f %9.2f %10.0f %7.2f  (%zu triangles; OpenMesh %zu faces)\n",
                std::filesystem::path(f).filename().c_str(), mb, one * 1e3, mb / one, all * 1e3, mb / all, theirs * 1e3,
                mb / theirs, theirs / all, ourTriangles, theirFaces);
  }
  return 0;
}
