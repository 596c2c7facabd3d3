// The cell table of grid file version 3 (docs/grid-format.md, item 9): the occupied cells' keys and primitive ids,
// delta-coded as LEB128 varints. At 1024^3 the bunny's table is a quarter of version 2's three flat arrays, so the
// file is written, synced and read in a quarter of the bytes.
#pragma once

#include <functional>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/byte_codec.h"
#include "vox/core/grid.h"

namespace vox {

// The table of a grid, encoded once (in parallel, in chunks of cells) and then handed to the payload's writer as
// many times as it streams the payload.
struct EncodedCellTable {
  uint64_t occupied = 0, references = 0;
  HugeVector<char> bytes;  // on huge pages: see encodeCellTable
};
// `progress`, when given, is asked (from worker threads) with a fraction in [0, 1] once per chunk of 2^15 cells;
// returning false cancels: vox::Error "grid file: encoding cancelled".
EncodedCellTable encodeCellTable(const Grid& grid, const std::function<bool(double)>& progress = {});

// Writes the table: u64 occupied, u64 references, u64 bytes, then the bytes.
void putCellTable(ByteWriter& w, const EncodedCellTable& table);

// Reads a table into grid.cellKeys, cellStart and primIds, checking as it decodes that keys ascend inside the grid
// (whose dims are read), ids ascend within a cell below `bounded`, and counts and bytes match exactly: the same
// guarantees as version 2's checks. Memory is bounded by the file: a cell takes at least 3 bytes, an id 1.
// `progress` asked every 2^16 cells; false cancels (vox::Error "NAME: reading cancelled").
void getCellTable(ByteReader& r, Grid& grid, uint64_t bounded, const std::function<bool(double)>& progress = {});

}  // namespace vox
