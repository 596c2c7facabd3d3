// The Distances section of grid files (docs/grid-format.md "Sections"): the narrow band of --sdf, written only for a
// grid that has one.
//
// Version 5 body: f64 half-width (smallest cell edges), u64 B (cells), u64 R (bytes of the runs), R bytes of runs,
// B f64 signed distances (finite). The keys (strictly ascending, inside the grid) are written as runs of
// consecutive keys, each two LEB128 varints: the cells skipped since the previous run (the first run: its first
// key; never 0 after the first run, so runs neither touch nor overlap and a band has one encoding) and the run's
// length less one. A band is shells of cells around the surface, so its keys come in runs along x (13.7 cells on
// average for the bunny at 256 and 1024): 0.2 bytes a key instead of 8, and the file is the values and little else.
//
// Version 4 body: f64 half-width, u64 B, B u64 keys, B f64 signed distances. Still read.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "io/grid_sections.h"
#include "vox/core/exact_number.h"
#include "vox/core/varint.h"

namespace vox {

namespace {

constexpr uint64_t kProgressCells = uint64_t(1) << 16;  // progress is asked once per this many cells

// The runs of consecutive keys in `keys` (sorted, unique), as varints (see the top of the file). About 20 ms for
// the bunny's 14.8 million keys at 1024^3, once per write (the section's memo).
std::string encodeRuns(const std::vector<uint64_t>& keys) {
  std::string bytes;
  size_t used = 0;
  uint64_t next = 0;  // the first key the next run may start at
  for (size_t i = 0; i < keys.size();) {
    size_t j = i + 1;
    while (j < keys.size() && keys[j] == keys[j - 1] + 1) ++j;
    if (bytes.size() - used < 20) bytes.resize(std::max<size_t>(4096, 2 * bytes.size()));  // room for two varints
    uint8_t* const start = reinterpret_cast<uint8_t*>(bytes.data()) + used;
    const uint8_t* const end = putVarint(putVarint(start, keys[i] - next), j - i - 1);
    used += size_t(end - start);
    next = keys[j - 1] + 1;
    i = j;
  }
  bytes.resize(used);
  return bytes;
}

void ask(const SectionContext& context, size_t position, const ByteReader& r) {
  if (context.progress && !context.progress(double(position) / double(std::max<size_t>(context.fileSize, 1))))
    fail<Error>(r.name(), ": reading cancelled");
}

double getHalfWidth(ByteReader& r) {
  const double halfWidth = r.getFinite("distance band half-width");
  // 64: kMaxSdfHalfWidth (vox/distance/sdf.h), the widest band the writers make.
  if (!(halfWidth > 0) || halfWidth > 64)
    r.corrupt("distance band half-width " + exactNumber(halfWidth) + " outside (0, 64] cell edges");
  return halfWidth;
}

// Version 4's keys: a flat array, checked ascending and inside the grid.
std::vector<uint64_t> getFlatKeys(ByteReader& r, const Grid& grid, const SectionContext& context) {
  const size_t at = r.position();
  std::vector<uint64_t> keys = r.getArray<uint64_t>("distance band cell");
  r.need(keys.size() * sizeof(double));
  for (size_t i = 0; i < keys.size(); ++i) {
    if (i % kProgressCells == 0) ask(context, at + 8 * i, r);
    if (keys[i] >= grid.cellCount()) r.corrupt("distance band cell " + std::to_string(keys[i]) + " outside the grid");
    if (i > 0 && keys[i] <= keys[i - 1]) r.corrupt("distance band cells not strictly ascending");
  }
  return keys;
}

// Version 5's keys: the count, then the runs, decoded with every run checked inside the grid and after the one
// before. Memory is bounded by the file: the count must leave room for its 8-byte values.
std::vector<uint64_t> getRunKeys(ByteReader& r, const Grid& grid, const SectionContext& context) {
  const uint64_t count = r.get<uint64_t>();
  const uint64_t size = r.get<uint64_t>();
  const size_t bodyAt = r.position();
  const std::string_view body = r.take(size);
  if (count > r.remaining() / sizeof(double) || count > grid.cellCount())
    r.corrupt("distance band count " + std::to_string(count) + " exceeds the file or the grid");
  const uint8_t* p = reinterpret_cast<const uint8_t*>(body.data());
  const uint8_t* const base = p;
  const uint8_t* const end = p + body.size();
  const auto bad = [&](const char* what) {
    fail<InputError>(r.name(), ": byte ", bodyAt + size_t(p - base), ": distance band runs: ", what);
  };
  const auto varint = [&] {
    uint64_t v = 0;
    const VarintStatus status = getVarint(p, end, v);
    if (status == VarintStatus::Truncated) bad("truncated number");
    if (status == VarintStatus::Malformed) bad("number too large or not in its shortest form");
    return v;
  };
  const uint64_t cells = grid.cellCount();
  std::vector<uint64_t> keys(count);
  uint64_t done = 0, next = 0;  // next: the first key the next run may start at
  uint64_t askAt = 0;           // progress is asked when `done` passes it, so a long run of a hostile file too
  while (done < count) {
    const uint64_t gap = varint(), more = varint();
    if (done > 0 && gap == 0) bad("runs touch (two runs that should have been one)");
    if (next >= cells || gap >= cells - next) bad("run outside the grid");
    const uint64_t first = next + gap;
    if (more >= cells - first) bad("run outside the grid");
    if (more >= count - done) bad("more cells than the band's count");
    for (uint64_t i = 0; i <= more; ++i) {
      if (done + i == askAt) {
        ask(context, bodyAt + size_t(p - base), r);
        askAt += kProgressCells;
      }
      keys[done + i] = first + i;
    }
    done += more + 1;
    next = first + more + 1;
  }
  if (p != end) bad("bytes left after the band's last run");
  return keys;
}

// B finite doubles, memcpy'd a slice at a time with progress between slices.
std::vector<double> getValues(ByteReader& r, size_t count, const SectionContext& context) {
  r.need(count * sizeof(double));
  std::vector<double> values(count);
  for (size_t i = 0; i < count; i += kProgressCells) {
    ask(context, r.position(), r);
    const size_t n = std::min<size_t>(count - i, kProgressCells);
    const std::string_view bytes = r.take(n * sizeof(double));
    std::memcpy(values.data() + i, bytes.data(), bytes.size());
    for (size_t k = i; k < i + n; ++k)
      if (!std::isfinite(values[k]))
        fail<InputError>(r.name(), ": byte ", r.position() - bytes.size() + (k - i) * sizeof(double),
                         ": signed distance is not a finite number");
  }
  return values;
}

}  // namespace

bool hasDistancesSection(const Scene&, const Grid& grid) { return grid.sdfHalfWidth > 0; }

void putDistancesSection(ByteWriter& w, const Scene&, const Grid& grid, std::string& runs) {
  if (runs.empty()) runs = encodeRuns(grid.sdfKeys);  // empty again only for an empty band, which costs nothing
  w.put(grid.sdfHalfWidth);
  w.put(uint64_t(grid.sdfKeys.size()));
  w.put(uint64_t(runs.size()));
  w.putBytes(runs);
  w.putBytes({reinterpret_cast<const char*>(grid.sdfValues.data()), grid.sdfValues.size() * sizeof(double)});
}

void getDistancesSection(ByteReader& r, Scene&, Grid& grid, const SectionContext& context) {
  const double halfWidth = getHalfWidth(r);
  std::vector<uint64_t> keys = context.version >= 5 ? getRunKeys(r, grid, context) : getFlatKeys(r, grid, context);
  std::vector<double> values = getValues(r, keys.size(), context);
  grid.sdfHalfWidth = halfWidth;
  grid.sdfKeys = std::move(keys);
  grid.sdfValues = std::move(values);
}

}  // namespace vox
