// Progress and cancellation of reading one scene file (loadScene's `progress`), as voxelizeScene's: chunks read in
// parallel report as they finish, serial loops ask every 4096th step from the calling thread, and once the callback
// says stop the read throws Error("PATH: reading cancelled"). The Python binding looks at Ctrl-C in the callback when
// the calling thread makes it: a few hundred MB of OBJ take seconds to read.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "vox/core/error.h"
#include "vox/core/resize_in_steps.h"

namespace vox {

class ImportProgress {
 public:
  // `callback` may be empty; both must outlive this.
  ImportProgress(const std::function<bool(double)>& callback, const std::string& path)
      : callback_(callback), path_(path) {}

  // From any thread: `fraction` of the read is done. False once cancelled.
  bool report(double fraction) {
    if (cancelled()) return false;
    if (callback_ && !callback_(fraction)) cancelled_ = true;
    return !cancelled();
  }
  // Step i of a serial loop on the calling thread, `fraction` of the read done: asks every 4096th step, throws when
  // cancelled.
  void step(uint64_t i, double fraction) {
    if ((i & 4095) != 0) return;
    report(fraction);
    check();
  }
  // v.resize(n) in steps of 8 MiB, asking between them at `fraction`: a resize zero-fills fresh pages on the calling
  // thread alone, 0.18 s for the arrays of a 286 MB OBJ. Values as resize gives.
  template <typename Vector>
  void resize(Vector& v, size_t n, double fraction) {
    resizeInSteps(v, n, typename Vector::value_type{}, [&] {
      report(fraction);
      check();
    });
  }
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  void check() const {
    if (cancelled()) fail<Error>(path_, ": reading cancelled");
  }

 private:
  const std::function<bool(double)>& callback_;
  const std::string& path_;
  std::atomic<bool> cancelled_{false};
};

}  // namespace vox
