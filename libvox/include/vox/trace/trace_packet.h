// Tracing coherent rays together: a packet walks the grid slice by slice along its major axis (Wald et al. 2006,
// "Ray Tracing Animated Scenes using Coherent Grid Traversal"), visiting for each slice the rectangle of cells that
// bounds every ray of the packet in it, and testing each primitive of those cells against all the packet's rays at
// once (vectorized). Primary rays of one image tile are the intended use.
#pragma once

#include <cstdint>
#include <span>

#include "vox/trace/accel.h"
#include "vox/trace/ray.h"
#include "vox/trace/traverse.h"

namespace vox {

inline constexpr uint32_t kMaxPacketRays = 64;

// hits[i] = the nearest hit of rays[i], equal bit for bit (t and primitive) to traceRay(accel, rays[i]) and to the
// brute force whenever every primitive is in every cell its surface meets (exact, sat and bbox grids); on a
// `center` grid it may find hits that traceRay misses. Any rays are accepted: rays that do not share a travel
// direction on some axis, or are far from coherent, are traced one by one. Packets longer than kMaxPacketRays are
// cut. `stats` counts cells once per packet and tests once per ray (may be null).
void tracePacket(const Accel& accel, std::span<const Ray> rays, std::span<Hit> hits, TraceStats* stats = nullptr);

// occluded[i] = occluded(accel, rays[i]) (shadow rays), under the same conditions: equal to the brute force on exact,
// sat and bbox grids, may differ from occluded() on a `center` grid.
void occludedPacket(const Accel& accel, std::span<const Ray> rays, std::span<bool> occluded,
                    TraceStats* stats = nullptr);

}  // namespace vox
