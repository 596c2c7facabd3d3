// Mailboxing (Amanatides & Woo 1987; Kirk & Arvo): a direct-mapped cache of the primitive ids a ray (or a packet of
// rays) has already tested, so that a primitive spanning many cells is tested once. It lives on the stack of the
// tracing call, so it needs no synchronisation. A collision only repeats a test, which returns the same t, and a
// hit that is not closer() than the one it already gave changes nothing: correctness never depends on it.
#pragma once

#include <cstdint>
#include <cstring>

namespace vox {

template <uint32_t Size>
struct Mailbox {
  static_assert((Size & (Size - 1)) == 0, "a power of two");
  uint32_t ids[Size];
  // Filled by vector stores: a memset of 256 bytes is a library call (3% of an incoherent single ray, issue 12).
  Mailbox() {
    typedef uint32_t Fill __attribute__((vector_size(16)));
    const Fill all = ~Fill{};
    for (uint32_t k = 0; k < Size; k += 4) std::memcpy(ids + k, &all, sizeof(all));
  }
  // True when `id` was already tested; records it otherwise.
  bool seen(uint32_t id) {
    uint32_t& slot = ids[id & (Size - 1)];
    if (slot == id) return true;
    slot = id;
    return false;
  }
};

}  // namespace vox
