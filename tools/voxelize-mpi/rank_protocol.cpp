#include "rank_protocol.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "vox/core/error.h"
#include "vox/core/tool.h"

namespace vox::mpi {

namespace {

struct Packer {
  std::string bytes;
  template <typename T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void put(const std::string& s) {
    put(uint64_t(s.size()));
    bytes += s;
  }
};

struct Unpacker {
  const std::string& bytes;
  size_t pos = 0;
  template <typename T>
  void get(T& v) {
    VOX_CHECK(pos + sizeof(T) <= bytes.size());
    std::memcpy(&v, bytes.data() + pos, sizeof(T));
    pos += sizeof(T);
  }
  void get(std::string& s) {
    uint64_t n = 0;
    get(n);
    VOX_CHECK(n <= bytes.size() - pos);
    s = bytes.substr(pos, n);
    pos += n;
  }
};

}  // namespace

double peakMemoryMb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

std::string packOutcome(const Outcome& o) {
  Packer p;
  p.put(o.code);
  p.put(o.message);
  p.put(o.seconds);
  p.put(o.peakMb);
  p.put(o.items);
  p.put(uint64_t(o.bricks.size()));
  for (const auto& e : o.bricks) {
    for (uint32_t i : e.index) p.put(i);
    p.put(e.file);
    p.put(e.fileSize);
    p.put(e.fileChecksum);
    p.put(e.occupied);
    p.put(e.references);
    p.put(e.solid);
  }
  p.put(uint64_t(o.scenes.size()));
  for (const auto& s : o.scenes) {
    p.put(s.index);
    p.put(s.code);
    p.put(s.message);
  }
  return p.bytes;
}

Outcome unpackOutcome(const std::string& bytes) {
  Outcome o;
  Unpacker u{bytes};
  u.get(o.code);
  u.get(o.message);
  u.get(o.seconds);
  u.get(o.peakMb);
  u.get(o.items);
  uint64_t n = 0;
  u.get(n);
  VOX_CHECK(n <= bytes.size());
  o.bricks.resize(n);
  for (auto& e : o.bricks) {
    for (uint32_t& i : e.index) u.get(i);
    u.get(e.file);
    u.get(e.fileSize);
    u.get(e.fileChecksum);
    u.get(e.occupied);
    u.get(e.references);
    u.get(e.solid);
  }
  u.get(n);
  VOX_CHECK(n <= bytes.size());
  o.scenes.resize(n);
  for (auto& s : o.scenes) {
    u.get(s.index);
    u.get(s.code);
    u.get(s.message);
  }
  VOX_CHECK(u.pos == bytes.size());
  return o;
}

int32_t setFailure(const std::vector<Outcome>& all, std::string& message) {
  for (size_t r = 0; r < all.size(); ++r)
    if (all[r].code != kExitOk) {
      message = (all.size() > 1 ? "rank " + std::to_string(r) + ": " : std::string()) + all[r].message;
      return all[r].code;
    }
  return kExitOk;
}

GridSetManifest mergeBrickEntries(const GridSetManifest& set, const std::vector<Outcome>& all) {
  GridSetManifest m = set;
  for (const auto& o : all) m.entries.insert(m.entries.end(), o.bricks.begin(), o.bricks.end());
  std::erase_if(m.entries, [](const BrickEntry& e) { return e.occupied == 0; });
  std::sort(m.entries.begin(), m.entries.end(), [&](const BrickEntry& a, const BrickEntry& b) {
    return brickNumber(m.bricks, a.index) < brickNumber(m.bricks, b.index);
  });
  return m;
}

BatchSummary summarizeBatch(const std::vector<Outcome>& all) {
  std::vector<SceneResult> results;
  for (const auto& o : all) results.insert(results.end(), o.scenes.begin(), o.scenes.end());
  std::sort(results.begin(), results.end());
  BatchSummary summary;
  for (const SceneResult& r : results)
    if (r.code != kExitOk) {
      summary.code = std::max(summary.code, int(r.code));
      summary.errors.push_back(r.message);
    }
  return summary;
}

std::string rankStatsText(const std::vector<Outcome>& all, double totalSeconds) {
  std::string text;
  char line[256];
  for (size_t r = 0; r < all.size(); ++r) {
    std::snprintf(line, sizeof line, "rank_%zu: items %llu work_seconds %.3f peak_memory_mb %.1f\n", r,
                  (unsigned long long)all[r].items, all[r].seconds, all[r].peakMb);
    text += line;
  }
  double peak = 0;
  for (const auto& o : all) peak = std::max(peak, o.peakMb);
  std::snprintf(line, sizeof line, "ranks: %zu\ntotal_seconds: %.6f\nmax_peak_memory_mb: %.1f\n", all.size(),
                totalSeconds, peak);
  return text + line;
}

}  // namespace vox::mpi
