#include "vox/core/progress.h"

#include <unistd.h>

#include <cstdio>

namespace vox {

ProgressBar::ProgressBar(std::string label, bool quiet)
    : label_(std::move(label)),
      enabled_(!quiet && ::isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      lastDraw_(start_) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  // Short jobs stay silent; long ones redraw at 10 Hz.
  if (now - start_ < std::chrono::milliseconds(500) || now - lastDraw_ < std::chrono::milliseconds(100)) return;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  lastDraw_ = now;
  constexpr int kWidth = 40;
  const double f = fraction < 0 ? 0 : (fraction > 1 ? 1 : fraction);
  const int filled = int(f * kWidth);
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", label_.c_str(), filled, "########################################",
               kWidth - filled, "", int(f * 100));
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  std::lock_guard lock(mutex_);
  if (drawn_) {
    std::fprintf(stderr, "\r%*s\r", int(label_.size()) + 50, "");
    std::fflush(stderr);
    drawn_ = false;
  }
}

}  // namespace vox
