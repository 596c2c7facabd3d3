// Long calls: the GIL released, worker threads, Ctrl-C and progress (binding.h, Interrupt).
#include <tbb/task_arena.h>

#include <map>

#include "binding.h"
#include "vox/core/error.h"
#include "vox/io/input_file.h"

namespace voxpy {

Interrupt::Interrupt(py::object progress)
    : caller_(std::this_thread::get_id()),
      lastPoll_(std::chrono::steady_clock::now()),
      progress_(std::move(progress)) {}

Interrupt::~Interrupt() = default;

bool Interrupt::poll(double fraction) {
  if (cancelled()) return false;
  // The largest fraction any thread reported: workers finish out of order.
  double seen = fraction_.load(std::memory_order_relaxed);
  while (fraction > seen && !fraction_.compare_exchange_weak(seen, fraction, std::memory_order_relaxed)) {
  }
  if (std::this_thread::get_id() != caller_) return true;
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - lastPoll_).count() < kPollSeconds && fraction < 1) return true;
  lastPoll_ = now;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) {
    error_ = std::make_unique<py::error_already_set>();
    cancelled_ = true;
    return false;
  }
  const double done = fraction_.load(std::memory_order_relaxed);
  if (!progress_.is_none() && done != reported_) {
    reported_ = done;
    try {
      progress_(done);
    } catch (py::error_already_set& e) {
      error_ = std::make_unique<py::error_already_set>(std::move(e));
      cancelled_ = true;
      return false;
    }
  }
  return true;
}

void Interrupt::finish(bool completed) {
  if (error_) {
    auto error = std::move(error_);
    throw py::error_already_set(std::move(*error));
  }
  if (completed && !progress_.is_none() && reported_ < 1) {
    reported_ = 1;
    progress_(1.0);
  }
  // A signal that arrived after the last poll: Python runs its handler at the next bytecode anyway.
}

py::object progressCallable(const py::object& progress, const char* label) {
  if (progress.is_none()) return py::none();
  if (isBool(progress)) {
    if (!boolArg(progress, "progress")) return py::none();
    return py::module_::import("libvox._progress").attr("bar")(label);
  }
  if (!PyCallable_Check(progress.ptr()))
    failType("progress must be None, a bool or a callable taking the fraction done, not ", typeName(progress));
  return progress;
}

void inArena(std::optional<int> threads, const std::function<void()>& body) {
  if (!threads) {
    body();
    return;
  }
  // One arena per thread count and per calling thread, kept: making one costs microseconds a call, and an arena
  // shared by two Python threads would make them take turns.
  thread_local std::map<int, std::unique_ptr<tbb::task_arena>> arenas;
  std::unique_ptr<tbb::task_arena>& arena = arenas[*threads];
  if (!arena) arena = std::make_unique<tbb::task_arena>(*threads);
  arena->execute(body);
}

uint64_t memoryBudget() {
  static const uint64_t budget = vox::memoryBudgetBytes();  // as the tools: read once per process
  return budget;
}

}  // namespace voxpy
