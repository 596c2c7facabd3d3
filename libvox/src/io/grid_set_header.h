// The 32-byte header shared by grid-set manifests and brick files (the grid file's layout, docs/grid-format.md):
// magic, u32 version, u32 flags (0), u64 payload size, u64 checksum of the payload.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include "io/byte_codec.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"

namespace vox {

inline constexpr size_t kSetHeaderSize = 32;
inline constexpr char kSetMagic[8] = {'V', 'O', 'X', 'G', 'S', 'E', 'T', '\n'};
inline constexpr char kBrickMagic[8] = {'V', 'O', 'X', 'B', 'R', 'C', 'K', '\n'};

// True when `name` holds a control byte (below 0x20, or DEL). Names are printed in one-line errors, which a newline
// would split: readers refuse such names in a manifest, and the writer refuses to make them.
inline bool hasControlByte(const std::string& name) {
  return std::any_of(name.begin(), name.end(),
                     [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

// The header's checksum field of a file's bytes (0 when too short).
inline uint64_t headerChecksum(const std::string& fileBytes) {
  uint64_t c = 0;
  if (fileBytes.size() >= kSetHeaderSize) std::memcpy(&c, fileBytes.data() + 24, 8);
  return c;
}

inline std::string withSetHeader(const char (&magic)[8], uint32_t version, const std::string& payload) {
  ByteWriter h;
  h.bytes().append(magic, 8);
  h.put(version);
  h.put(uint32_t(0));
  h.put(uint64_t(payload.size()));
  h.put(gridChecksum(payload.data(), payload.size()));
  return h.bytes() + payload;
}

// Checks magic, flags, size and checksum; returns the version (1 .. maxVersion). `what` names the kind of file.
inline uint32_t checkSetHeader(const std::string& bytes, const std::string& name, const char (&magic)[8],
                               uint32_t maxVersion, const char* what) {
  ByteReader r(bytes, 0, name);
  r.need(kSetHeaderSize);
  if (std::memcmp(bytes.data(), magic, 8) != 0) r.corrupt(std::string("not a ") + what + " (bad magic)");
  ByteReader h(bytes, 8, name);
  const uint32_t version = h.get<uint32_t>();
  if (version == 0 || version > maxVersion)
    h.corrupt(std::string(what) + " version " + std::to_string(version) + " (this reader knows 1 to " +
              std::to_string(maxVersion) + ")");
  if (h.get<uint32_t>() != 0) h.corrupt("unknown flags");
  const uint64_t size = h.get<uint64_t>();
  if (size != bytes.size() - kSetHeaderSize) {
    if (size > bytes.size() - kSetHeaderSize)
      fail<InputError>(name, ": truncated at byte ", bytes.size(), " (header promises ", kSetHeaderSize + size,
                       " bytes)");
    h.corrupt("payload size " + std::to_string(size) + " does not match the file");
  }
  if (h.get<uint64_t>() != gridChecksum(bytes.data() + kSetHeaderSize, size)) h.corrupt("checksum mismatch");
  return version;
}

}  // namespace vox
