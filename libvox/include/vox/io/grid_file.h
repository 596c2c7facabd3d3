// The grid file (.vgrid): a scene and its grid in one self-contained, checksummed, little-endian binary file.
// Layout in docs/grid-format.md.
#pragma once

#include <functional>
#include <string>

#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox {

// Version 5: the Distances section's keys as runs of consecutive keys (the bunny's band file at 1024^3 in 144 MB
// instead of 259). Version 4: the Distances and Fractions sections (--sdf, --fraction); a grid with fractions and
// no distances is still written as version 4. A grid with neither is still written as version 3, byte for byte what
// earlier builds wrote and read. Version 3: the cell table delta-coded (a quarter of version 2's bytes at 1024^3).
// Versions 4, 2 (solid cells as runs, optional tagged sections) and 1 still read.
inline constexpr uint32_t kGridFileVersion = 5;

// The version a grid is written in: 5 when it holds distances, 4 when it holds fractions only, 3 otherwise.
uint32_t gridFileVersionFor(const Grid& grid);

struct GridFile {
  Scene scene;
  Grid grid;
};

// Writes to `path` through a temporary file in the same folder and a rename, so a failure leaves no partial file.
// Throws OutputError naming the path.
// Where writeGridFile's time went (vox-voxelize --stats): encoding and writing the bytes, and making them durable
// (fsync of the file, rename, fsync of the folder).
struct WriteTimes {
  double writeSeconds = 0;
  double syncSeconds = 0;
};
// `progress`, when given, is called with a fraction in [0, 1] at least every 64 KiB written (and between the passes);
// returning false cancels: vox::Error "PATH: write cancelled", the old output untouched (Ctrl-C in Python's save).
void writeGridFile(const std::string& path, const Scene& scene, const Grid& grid, WriteTimes* times = nullptr,
                   const std::function<bool(double)>& progress = {});

// Reads and checks every count, offset, id and the checksum. Throws InputError naming the path and the byte offset
// for a truncated, corrupt or newer-version file. `progress`, when given, is asked with a fraction in [0, 1] at least
// every 2^16 cells (of the cell table and the distance band) decoded; returning false cancels: vox::Error "NAME:
// reading cancelled" (Ctrl-C in libvox.load).
GridFile readGridFile(const std::string& path, const std::function<bool(double)>& progress = {});

// The checksum of docs/grid-format.md over a payload (the bytes after the 32-byte header).
uint64_t gridChecksum(const char* payload, size_t size);

// The same on bytes in memory (fuzzing, tests). `name` is used in error messages. `version` 2 writes the previous
// layout, for tests that old files still read. The grid must be well-formed (every cell's offsets inside primIds,
// as voxelizeScene and decodeGridFile make it): version 3's encoder reads each cell's ids. Version 0: the one
// gridFileVersionFor names. It encodes what it is given (tests make bad files with it); the writers of real
// output (writeGridFile, pickling) call checkGridBeforeWrite first.
// `progress` as writeGridFile's (pickling's Ctrl-C).
std::string encodeGridFile(const Scene& scene, const Grid& grid, uint32_t version = 0,
                           const std::function<bool(double)>& progress = {});
GridFile decodeGridFile(const std::string& bytes, const std::string& name,
                        const std::function<bool(double)>& progress = {});

}  // namespace vox
