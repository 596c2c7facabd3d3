// A progress bar on stderr for the tools: quiet when stderr is not a terminal or when asked.
// Lives in the library so every tool draws the same bar; the library's algorithms never call it themselves,
// they take a std::function callback.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace vox {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet);
  ~ProgressBar();
  // Thread-safe; draws at most every 100 ms and only after the work has run for half a second.
  void update(double fraction);
  void finish();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point lastDraw_;
  std::mutex mutex_;
};

}  // namespace vox
