#include "vox/export/npz_writer.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/memory_budget.h"

namespace vox {

namespace {

// One .npy file (format version 1.0): magic, header length, a Python dict literal padded with spaces to a multiple
// of 64 bytes and ended by a newline, then the raw little-endian data.
std::string npyHeader(const char* descr, const std::vector<uint64_t>& shape, bool fortran) {
  std::string dict =
      std::string("{'descr': '") + descr + "', 'fortran_order': " + (fortran ? "True" : "False") + ", 'shape': (";
  for (size_t i = 0; i < shape.size(); ++i)
    dict += std::to_string(shape[i]) + (shape.size() == 1 || i + 1 < shape.size() ? ", " : "");
  dict += "), }";
  const size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string header("\x93NUMPY\x01\x00", 8);
  const uint16_t len = uint16_t(dict.size());
  header.append(reinterpret_cast<const char*>(&len), 2);
  return header + dict;
}

template <typename T>
void put(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// A zip archive of stored entries written in one pass: each entry's CRC and size are known before its local header
// (the entry is built in memory first), and the central directory follows the last entry. The data is checksummed
// and written in chunks, each reported to `progress` (a fraction of `expectedBytes`, each byte counted twice), so
// that Ctrl-C stops a save of gigabytes within a chunk (issue 45: 0.55 s past the signal with one call per array).
class ZipWriter {
 public:
  ZipWriter(std::ostream& out, uint64_t expectedBytes, const std::function<void(double)>& progress)
      : out_(out), expected_(2.0 * double(expectedBytes)), progress_(progress) {}

  void add(const std::string& name, const std::string& header, const void* data, uint64_t bytes) {
    uLong crc = crc32(0L, Z_NULL, 0);
    crc = crc32_z(crc, reinterpret_cast<const Bytef*>(header.data()), header.size());
    const auto* bytesIn = static_cast<const Bytef*>(data);
    for (uint64_t at = 0; at < bytes; at += kChunk) {
      const uint64_t n = std::min(kChunk, bytes - at);
      crc = crc32_z(crc, bytesIn + at, n);
      report(n);
    }
    const uint64_t size = header.size() + bytes;
    Entry e{name, uint32_t(crc), uint32_t(size), uint32_t(offset_)};
    std::string local;
    put<uint32_t>(local, 0x04034b50);
    putCommon(local, e);
    local += name;
    write(local.data(), local.size());
    write(header.data(), header.size());
    for (uint64_t at = 0; at < bytes; at += kChunk) {
      const uint64_t n = std::min(kChunk, bytes - at);
      write(static_cast<const char*>(data) + at, n);
      report(n);
    }
    entries_.push_back(e);
  }

  void finish() {
    const uint64_t start = offset_;
    std::string dir;
    for (const Entry& e : entries_) {
      put<uint32_t>(dir, 0x02014b50);
      put<uint16_t>(dir, 20);  // made by: version 2.0
      putCommon(dir, e);
      put<uint16_t>(dir, 0);  // comment length
      put<uint16_t>(dir, 0);  // disk number
      put<uint16_t>(dir, 0);  // internal attributes
      put<uint32_t>(dir, 0);  // external attributes
      put<uint32_t>(dir, e.offset);
      dir += e.name;
    }
    const uint32_t dirSize = uint32_t(dir.size());
    put<uint32_t>(dir, 0x06054b50);  // end of central directory
    put<uint16_t>(dir, 0);
    put<uint16_t>(dir, 0);
    put<uint16_t>(dir, uint16_t(entries_.size()));
    put<uint16_t>(dir, uint16_t(entries_.size()));
    put<uint32_t>(dir, dirSize);
    put<uint32_t>(dir, uint32_t(start));
    put<uint16_t>(dir, 0);
    write(dir.data(), dir.size());
  }

  uint64_t bytes() const { return offset_; }

 private:
  struct Entry {
    std::string name;
    uint32_t crc, size, offset;
  };
  // The fields local headers and central directory entries share, from "version needed" to the extra field length.
  static void putCommon(std::string& s, const Entry& e) {
    put<uint16_t>(s, 20);    // version needed: 2.0
    put<uint16_t>(s, 0);     // flags
    put<uint16_t>(s, 0);     // stored
    put<uint16_t>(s, 0);     // time
    put<uint16_t>(s, 0x21);  // date: 1980-01-01
    put<uint32_t>(s, e.crc);
    put<uint32_t>(s, e.size);
    put<uint32_t>(s, e.size);
    put<uint16_t>(s, uint16_t(e.name.size()));
    put<uint16_t>(s, 0);
  }
  static constexpr uint64_t kChunk = uint64_t(16) << 20;

  void report(uint64_t n) {
    done_ += double(n);
    if (progress_) progress_(std::min(1.0, done_ / expected_));
  }
  void write(const void* data, uint64_t n) {
    out_.write(static_cast<const char*>(data), std::streamsize(n));
    offset_ += n;
  }

  std::ostream& out_;
  const double expected_;
  const std::function<void(double)>& progress_;
  double done_ = 0;
  uint64_t offset_ = 0;
  std::vector<Entry> entries_;
};

template <typename T>
void addArray(ZipWriter& zip, const char* name, const char* descr, const std::vector<uint64_t>& shape, bool fortran,
              const std::vector<T>& values) {
  zip.add(std::string(name) + ".npy", npyHeader(descr, shape, fortran), values.data(), values.size() * sizeof(T));
}

}  // namespace

uint64_t writeNpz(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress) {
  // Every key below indexes a dense array of cellCount() entries: checked first, so that no grid, however it was
  // made, writes out of bounds (issue 45: a band with keys past the grid overflowed the heap).
  checkGridBeforeWrite(grid, "npz export");
  const uint64_t cells = grid.cellCount();
  const bool sdf = grid.sdfHalfWidth > 0, fraction = !grid.fractions.empty();
  const uint64_t total = cells * (2 + (sdf ? 8 : 0) + (fraction ? 8 : 0)) + 4096;
  if (total > kMaxNpzBytes)
    fail<LimitError>("grid of ", grid.dims[0], " x ", grid.dims[1], " x ", grid.dims[2], " cells: its .npz would take ",
                     total >> 20, " MiB, over the 4 GiB of the zip format; export .vdb (sparse) instead");
  checkMemory(double(cells) * (sdf || fraction ? 8 : 1), "npz export", "one dense array");
  const std::vector<uint64_t> shape{grid.dims[0], grid.dims[1], grid.dims[2]};
  ZipWriter zip(out, total, progress);
  {
    std::vector<uint8_t> occupancy(cells, 0), solid(cells, 0);
    for (uint64_t key : grid.cellKeys) occupancy[key] = 1;
    for (const CellRun& r : grid.solidRuns) std::fill_n(solid.begin() + r.first, r.count, uint8_t(1));
    addArray(zip, "occupancy", "|u1", shape, true, occupancy);
    addArray(zip, "solid", "|u1", shape, true, solid);
  }
  if (sdf) {
    std::vector<double> values(cells, std::numeric_limits<double>::quiet_NaN());
    for (size_t b = 0; b < grid.sdfKeys.size(); ++b) values[grid.sdfKeys[b]] = grid.sdfValues[b];
    addArray(zip, "sdf", "<f8", shape, true, values);
  }
  if (fraction) {
    std::vector<double> values(cells, 0.0);
    for (const CellRun& r : grid.solidRuns) std::fill_n(values.begin() + r.first, r.count, 1.0);
    for (size_t c = 0; c < grid.cellKeys.size(); ++c) values[grid.cellKeys[c]] = grid.fractions[c];
    addArray(zip, "fraction", "<f8", shape, true, values);
  }
  const std::vector<double> bounds{grid.bounds.lo.x, grid.bounds.lo.y, grid.bounds.lo.z,
                                   grid.bounds.hi.x, grid.bounds.hi.y, grid.bounds.hi.z};
  addArray(zip, "bounds", "<f8", {2, 3}, false, bounds);
  const std::vector<int64_t> dims{grid.dims[0], grid.dims[1], grid.dims[2]};
  addArray(zip, "dims", "<i8", {3}, false, dims);
  std::vector<double> transform(16, 0.0);  // world centre = lo + (index + 0.5) * cell, row-major 4x4
  for (int a = 0; a < 3; ++a) {
    const double cell = (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a];
    transform[a * 4 + a] = cell;
    transform[a * 4 + 3] = grid.bounds.lo[a] + 0.5 * cell;
  }
  transform[15] = 1;
  addArray(zip, "transform", "<f8", {4, 4}, false, transform);
  zip.finish();
  if (progress) progress(1.0);
  return zip.bytes();
}

}  // namespace vox
