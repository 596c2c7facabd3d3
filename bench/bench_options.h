// What the C++ benches of distances and volumes share: their options (--runs N, --threads T, --res N repeated, and
// a mesh path) and a clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace vox::bench {

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

struct BenchOptions {
  int runs = 3;
  int threads = 2;
  std::vector<uint32_t> resolutions;  // empty: the bench's own list
  std::string mesh;
};

// `defaults` with what argv says; `extra(flag, value)` is offered any other "--flag value" pair and returns whether
// it took it; any other argument is the mesh.
template <typename Extra>
BenchOptions parseBenchOptions(int argc, char** argv, BenchOptions defaults, const Extra& extra) {
  BenchOptions o = std::move(defaults);
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if (a == "--runs" && hasValue)
      o.runs = std::atoi(argv[++i]);
    else if (a == "--threads" && hasValue)
      o.threads = std::atoi(argv[++i]);
    else if (a == "--res" && hasValue)
      o.resolutions.push_back(uint32_t(std::atoi(argv[++i])));
    else if (hasValue && a.rfind("--", 0) == 0 && extra(a, argv[i + 1]))
      ++i;
    else
      o.mesh = a;
  }
  return o;
}

}  // namespace vox::bench
