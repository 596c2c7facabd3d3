// The speed-accuracy trade of the overlap methods and of the grid resolution (issue 5). Writes one CSV row per
// scene, resolution and method; bench/tradeoff.sh turns it into plots and docs/tradeoff.md.
// Usage: tradeoff OUT.csv [--small] [--threads N] [--size PIXELS] [--res R1,R2,...]
#include <tbb/global_control.h>

#include <cstring>
#include <iostream>
#include <sstream>

#include "tradeoff_core.h"

int main(int argc, char** argv) {
  const char* usage = "usage: tradeoff OUT.csv [--small] [--threads N] [--size PIXELS] [--res R1,R2,...]\n";
  if (argc >= 2 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))) {
    std::printf("%s  The speed-accuracy trade of the overlap methods and resolutions, one CSV row each.\n", usage);
    return 0;
  }
  if (argc < 2 || argv[1][0] == '-') {
    std::fprintf(stderr, "%s", usage);
    return 1;
  }
  bool small = false;
  int threads = 0;
  vox::bench::TradeoffOptions options;
  options.resolutions = {0, 8, 16, 32, 64, 128, 256};
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--small")) {
      small = true;
      options.resolutions = {0, 4, 8, 16};
      options.imageSize = 48;
    } else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--size") && i + 1 < argc) {
      options.imageSize = uint32_t(std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--res") && i + 1 < argc) {
      options.resolutions.clear();
      std::stringstream list(argv[++i]);
      std::string item;
      while (std::getline(list, item, ',')) {
        char* end = nullptr;
        const unsigned long r = std::strtoul(item.c_str(), &end, 10);
        if (item.empty() || *end != '\0' || r > 65536) {
          std::fprintf(stderr, "tradeoff: --res: not a resolution: '%s'\n", item.c_str());
          return 1;
        }
        options.resolutions.push_back(uint32_t(r));
      }
    } else {
      std::fprintf(stderr, "tradeoff: unknown option %s\n%s", argv[i], usage);
      return 1;
    }
  }
  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  try {
    std::ofstream out(argv[1]);
    out << vox::bench::csvHeader() << "\n";
    for (const auto& scene : vox::bench::tradeoffScenes(VOX_SEED_DIR, small)) {
      std::fprintf(stderr, "%s...\n", scene.name.c_str());
      for (const auto& row : vox::bench::measureTradeoff(scene, options))
        out << vox::bench::csvLine(row) << "\n" << std::flush;
    }
    if (!out) throw vox::OutputError(std::string(argv[1]) + ": cannot write");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tradeoff: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
