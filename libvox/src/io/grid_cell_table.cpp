// Cell table encoding: per occupied cell, in key order,
//   varint(key - previous key - 1)   (the first cell: its key)
//   varint(count - 1)
//   varint(zigzag(first id - previous cell's first id))   (the first cell: against 0)
//   varint(id - previous id - 1) for each further id of the cell.
// Neighbouring cells mostly hold the same triangles, so most values fit one byte. Varints are canonical (no
// trailing zero byte), so a grid has exactly one encoding.
#include "io/grid_cell_table.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>
#include <utility>

#include "vox/core/error.h"
#include "vox/core/huge_pages.h"
#include "vox/core/varint.h"

namespace vox {
namespace {

constexpr uint64_t kChunkCells = uint64_t(1) << 15;

uint64_t zigzag(int64_t v) { return (uint64_t(v) << 1) ^ uint64_t(v >> 63); }
int64_t unzigzag(uint64_t v) { return int64_t(v >> 1) ^ -int64_t(v & 1); }

// Calls emit(value) for every varint of cells [begin, end), in file order.
template <typename Emit>
void forEachValue(const Grid& grid, uint64_t begin, uint64_t end, Emit&& emit) {
  for (uint64_t c = begin; c < end; ++c) {
    emit(c == 0 ? grid.cellKeys[0] : grid.cellKeys[c] - grid.cellKeys[c - 1] - 1);
    const uint64_t from = grid.cellStart[c], to = grid.cellStart[c + 1];
    emit(to - from - 1);
    const int64_t previousFirst = c == 0 ? 0 : int64_t(grid.primIds[grid.cellStart[c - 1]]);
    emit(zigzag(int64_t(grid.primIds[from]) - previousFirst));
    for (uint64_t k = from + 1; k < to; ++k) emit(uint64_t(grid.primIds[k]) - grid.primIds[k - 1] - 1);
  }
}

}  // namespace

EncodedCellTable encodeCellTable(const Grid& grid, const std::function<bool(double)>& progress) {
  EncodedCellTable table;
  table.occupied = grid.cellKeys.size();
  table.references = grid.primIds.size();
  const size_t chunks = (table.occupied + kChunkCells - 1) / kChunkCells;
  auto cells = [&](size_t i) { return std::pair(i * kChunkCells, std::min(table.occupied, (i + 1) * kChunkCells)); };
  // Each chunk's size first, so that the chunks are encoded side by side into one buffer of exactly the table's
  // size. The buffer is fresh memory, on huge pages: on these machines a 4 KiB page fault costs about 10 us, and
  // with a fresh string per chunk the bunny's table at 1024^3 took 100 ms on one thread, mostly in page faults.
  std::vector<size_t> offset(chunks + 1, 0);
  // Ctrl-C while a 2048^3 grid's table is encoded (about 1 s for 10^8 cells) stops within a chunk.
  std::atomic<bool> stop{false};
  std::atomic<size_t> done{0};
  const auto proceed = [&] {
    if (progress && !stop.load(std::memory_order_relaxed) && !progress(0.5 * double(++done) / double(chunks)))
      stop = true;
    return !stop.load(std::memory_order_relaxed);
  };
  const auto checkStopped = [&] {
    if (stop) fail<Error>("grid file: encoding cancelled");
  };
  tbb::parallel_for(size_t(0), chunks, [&](size_t i) {
    if (!proceed()) return;
    size_t size = 0;
    forEachValue(grid, cells(i).first, cells(i).second, [&](uint64_t v) { size += varintSize(v); });
    offset[i + 1] = size;
  });
  checkStopped();
  for (size_t i = 0; i < chunks; ++i) offset[i + 1] += offset[i];
  table.bytes.reserve(offset[chunks]);
  table.bytes.resize(offset[chunks]);
  tbb::parallel_for(size_t(0), chunks, [&](size_t i) {
    if (!proceed()) return;
    uint8_t* p = reinterpret_cast<uint8_t*>(table.bytes.data()) + offset[i];
    forEachValue(grid, cells(i).first, cells(i).second, [&](uint64_t v) { p = putVarint(p, v); });
  });
  checkStopped();
  return table;
}

void putCellTable(ByteWriter& w, const EncodedCellTable& table) {
  w.put(table.occupied);
  w.put(table.references);
  w.put(uint64_t(table.bytes.size()));
  w.putBytes({table.bytes.data(), table.bytes.size()});
}

namespace {

// Reads the table's bytes; every failure names the byte it happened at.
class TableDecoder {
 public:
  TableDecoder(std::string_view bytes, size_t offset, const std::string& name)
      : p_(reinterpret_cast<const uint8_t*>(bytes.data())),
        end_(p_ + bytes.size()),
        base_(p_),
        offset_(offset),
        name_(name) {}

  [[noreturn]] void bad(const char* what) const {
    fail<InputError>(name_, ": cell table at byte ", offset_ + size_t(p_ - base_), ": ", what);
  }
  uint64_t varint() {
    uint64_t v = 0;
    const VarintStatus status = getVarint(p_, end_, v);
    if (status == VarintStatus::Truncated) bad("truncated number");
    if (status == VarintStatus::Malformed) bad("number too large or not in its shortest form");
    return v;
  }
  bool atEnd() const { return p_ == end_; }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
  const uint8_t* base_;
  size_t offset_;
  const std::string& name_;
};

}  // namespace

void getCellTable(ByteReader& r, Grid& grid, uint64_t bounded, const std::function<bool(double)>& progress) {
  const size_t at = r.position();
  const uint64_t occupied = r.get<uint64_t>(), references = r.get<uint64_t>(), size = r.get<uint64_t>();
  const size_t bodyAt = r.position();
  const std::string_view body = r.take(size);
  TableDecoder d(body, bodyAt, r.name());
  if (occupied > size / 3 || references > size || references < occupied)
    fail<InputError>(r.name(), ": cell table at byte ", at, ": ", occupied, " cells and ", references,
                     " references do not fit its ", size, " bytes");
  const uint64_t cells = grid.cellCount();
  const uint64_t idLimit = std::min<uint64_t>(bounded, uint64_t(std::numeric_limits<uint32_t>::max()) + 1);
  grid.cellKeys.reserve(occupied);
  grid.cellStart.reserve(occupied + 1);
  grid.primIds.reserve(references);
  grid.cellKeys.resize(occupied);
  grid.cellStart.resize(occupied + 1);
  grid.primIds.resize(references);
  uint64_t key = 0, ref = 0;
  int64_t previousFirst = 0;
  for (uint64_t c = 0; c < occupied; ++c) {
    if (progress && (c & 0xffff) == 0 && !progress(double(c) / double(occupied)))
      fail<Error>(r.name(), ": reading cancelled");
    const uint64_t gap = d.varint();
    const uint64_t next = c == 0 ? 0 : key + 1;  // key + 1 <= cells: key < cells
    if (next >= cells || gap >= cells - next) d.bad("cell key outside the grid");
    key = next + gap;
    grid.cellKeys[c] = key;
    grid.cellStart[c] = ref;
    const uint64_t more = d.varint();
    if (more >= references - ref) d.bad("more references than the table holds");
    const uint64_t first = d.varint();
    if (first > (uint64_t(1) << 34)) d.bad("primitive id out of range");
    const int64_t id = previousFirst + unzigzag(first);
    if (id < 0 || uint64_t(id) >= idLimit) d.bad("primitive id out of range");
    previousFirst = id;
    uint64_t last = uint64_t(id);
    grid.primIds[ref++] = uint32_t(last);
    for (uint64_t i = 0; i < more; ++i) {
      const uint64_t step = d.varint();
      if (step >= idLimit - last - 1) d.bad("primitive ids not ascending or out of range");
      last += step + 1;
      grid.primIds[ref++] = uint32_t(last);
    }
  }
  grid.cellStart[occupied] = ref;
  if (ref != references) d.bad("fewer references than the table's count");
  if (!d.atEnd()) d.bad("bytes left after the last cell");
}

}  // namespace vox
