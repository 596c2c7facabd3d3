// Command-line plumbing shared by the tools: the options every tool takes and --threads. CLI11 itself is in
// cli_app.h, included only by the files that build or parse a CLI::App: its header takes some ten seconds to compile
// in each file that includes it.
#pragma once

#include <tbb/global_control.h>

#include <memory>

namespace CLI {
class App;
}

namespace vox::cli {

// Options every tool takes.
struct CommonOptions {
  bool quiet = false;
  unsigned threads = 0;  // 0: all cores
};

// Limits TBB to the requested thread count for the lifetime of the returned object.
inline std::unique_ptr<tbb::global_control> limitThreads(unsigned threads) {
  if (threads == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

}  // namespace vox::cli
