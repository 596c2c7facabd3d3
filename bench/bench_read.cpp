// Reading meshes: vox::loadScene (our exact double reader, issue 26's "200 MB/s per thread") on one thread and on
// all, against OpenMesh's OBJ and PLY readers (floats, one thread) on the same files. Each load runs in a fresh
// process (this program started again with --child), as the tools read a file once: a load repeated inside one
// process finds its memory already mapped by the previous one and measures something no user runs. The timer
// starts at the load, after the process and TBB are up. Runs alternate; the best of --runs each; MB/s and the ratio
// of OpenMesh's time to ours on all threads.
//   build/bench/bench_read [--runs N] [--ours-only] [FILE...]   (default: the SheenCloth OBJ, the 69k bunny OBJ, PLY)
// --ours-only leaves OpenMesh out.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "vox/import/import.h"

namespace {

using Clock = std::chrono::steady_clock;
using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;

double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

long minorFaults() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// The child: one load of `path` by `who` ("ours" or "omesh") on `threads` threads; prints "SECONDS COUNT MINOR_FAULTS"
// (the page faults of the load itself).
int child(const std::string& who, int threads, const std::string& path) {
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  tbb::parallel_for(0, threads, [](int) {});  // the worker threads started before the clock
  const long faultsBefore = minorFaults();
  const auto start = Clock::now();
  size_t count = 0;
  double loaded = 0;
  long faults = 0;
  if (who == "ours") {
    const vox::Scene scene = vox::loadScene(path);  // timed without its release, as a tool holds it
    loaded = seconds(start);
    faults = minorFaults() - faultsBefore;
    count = scene.triangles.size();
  } else {
    OpenMeshTriangles mesh;
    if (!OpenMesh::IO::read_mesh(mesh, path)) return 1;
    loaded = seconds(start);
    faults = minorFaults() - faultsBefore;
    count = mesh.n_faces();
  }
  std::printf("%.9f %zu %ld\n", loaded, count, faults);
  return 0;
}

// One load in a fresh process: its seconds (or a negative number when it failed) and what it counted.
double timeInChild(const std::string& self, const std::string& who, int threads, const std::string& path, size_t& count,
                   long& faults) {
  const std::string command = "'" + self + "' --child " + who + " " + std::to_string(threads) + " '" + path + "'";
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return -1;
  double s = -1;
  if (std::fscanf(pipe, "%lf %zu %ld", &s, &count, &faults) != 3) s = -1;
  return ::pclose(pipe) == 0 ? s : -1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[1]) == "--child") return child(argv[2], std::atoi(argv[3]), argv[4]);
  const std::string self = std::filesystem::canonical("/proc/self/exe").string();
  int runs = 7;
  bool oursOnly = false;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf("usage: bench_read [--runs N] [--ours-only] [FILE...]\n");
      return 0;
    }
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
    long faults = 0, oneFaults = 0, allFaults = 0, theirFaults = 0;
    auto best = [&faults](double& into, long& intoFaults, double t) {
      if (t >= 0 && t < into) {
        into = t;
        intoFaults = faults;
      }
    };
    for (int r = 0; r < runs; ++r) {  // alternating, so that a noisy moment hits all three
      best(one, oneFaults, timeInChild(self, "ours", 1, f, ourTriangles, faults));
      best(all, allFaults, timeInChild(self, "ours", threads, f, ourTriangles, faults));
      if (!oursOnly) best(theirs, theirFaults, timeInChild(self, "omesh", 1, f, theirFaces, faults));
    }
    if (one >= 1e30 || all >= 1e30) {
      std::fprintf(stderr, "bench_read: %s: our reader failed\n", f.c_str());
      return 1;
    }
    std::printf("%-26s %7.2f %9.2f %9.0f %9.2f %9.0f", std::filesystem::path(f).filename().c_str(), mb, one * 1e3,
                mb / one, all * 1e3, mb / all);
    if (theirs < 1e30)
      std::printf(" %9.2f %10.0f %7.2f", theirs * 1e3, mb / theirs, theirs / all);
    else
      std::printf(" %9s %10s %7s", "-", "-", "-");
    std::printf("  (%zu triangles; OpenMesh %zu faces; page faults of the best loads %ld, %ld, %ld)\n", ourTriangles,
                theirFaces, oneFaults, allFaults, theirFaults);
  }
  return 0;
}
