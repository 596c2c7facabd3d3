// What fresh memory costs on this machine, 4 KiB pages against huge pages (docs/voxelize-speed.md, "Huge pages,
// whole"): for each kind, in alternating rounds, the time to zero a buffer of the file's size (its first touch) and
// then to read() the file into it, and the same read into a vox::HugeBuffer that was not zeroed first.
//   build/bench/page_cost [--rounds N] [FILE]     (default: the 4.8 MB SheenCloth OBJ)
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "vox/core/huge_buffer.h"

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

bool readInto(const std::string& path, char* into, size_t size) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  size_t got = 0;
  while (got < size) {
    const ssize_t r = ::read(fd, into + got, size - got);
    if (r <= 0) break;
    got += size_t(r);
  }
  ::close(fd);
  return got == size;
}

// Zeroes, then reads into, fresh anonymous memory of `size` bytes on 4 KiB pages (huge = false: MADV_NOHUGEPAGE)
// or on huge pages (2 MiB-aligned, MADV_HUGEPAGE).
void timeFresh(const std::string& path, size_t size, bool huge, double& zeroMs, double& readMs) {
  constexpr size_t kHuge = size_t{2} << 20;
  const size_t mapped = (size + 2 * kHuge) & ~(kHuge - 1);
  char* raw = static_cast<char*>(::mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  if (raw == MAP_FAILED) std::exit(1);
  char* at = reinterpret_cast<char*>((reinterpret_cast<uintptr_t>(raw) + kHuge - 1) & ~uintptr_t(kHuge - 1));
  (void)::madvise(at, size, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
  auto start = Clock::now();
  std::memset(at, 0, size);
  zeroMs = msSince(start);
  start = Clock::now();
  if (!readInto(path, at, size)) std::exit(1);
  readMs = msSince(start);
  ::munmap(raw, mapped);
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 7;
  std::string path = std::string(VOX_SEED_DIR) + "/meshes/derived/sheencloth_115k.obj";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--rounds" && i + 1 < argc) {
      rounds = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--help" || a == "-h") {
      std::printf(
          "page_cost [--rounds N] [FILE]\n  Zeroing and reading FILE into fresh memory, 4 KiB pages against huge "
          "pages (default: the SheenCloth OBJ).\n");
      return 0;
    } else if (a.rfind("--", 0) == 0) {
      std::fprintf(stderr, "page_cost: unknown option %s (see --help)\n", a.c_str());
      return 1;
    } else {
      path = a;
    }
  }
  std::error_code error;
  const size_t size = std::filesystem::file_size(path, error);
  if (error) {
    std::fprintf(stderr, "page_cost: %s: %s\n", path.c_str(), error.message().c_str());
    return 2;
  }
  std::printf("%zu bytes, %d rounds; medians in ms\n", size, rounds);
  std::vector<double> z4, r4, zh, rh, rb;
  for (int r = 0; r < rounds; ++r) {
    double z = 0, t = 0;
    timeFresh(path, size, false, z, t);
    z4.push_back(z), r4.push_back(t);
    timeFresh(path, size, true, z, t);
    zh.push_back(z), rh.push_back(t);
    const auto start = Clock::now();
    vox::HugeBuffer buffer(size);
    if (!readInto(path, buffer.data(), size)) return 1;
    rb.push_back(msSince(start));
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf("4 KiB pages: zero %.2f, then read %.2f\n", median(z4), median(r4));
  std::printf("huge pages:  zero %.2f, then read %.2f\n", median(zh), median(rh));
  std::printf("HugeBuffer, read without zeroing: %.2f\n", median(rb));
  return 0;
}
