// Optional parts of a grid file (docs/grid-format.md "Sections"), each a tagged section after the solid runs:
// u32 tag, u64 size, then `size` bytes of body. A section is written only when it has content; a reader refuses
// unknown and repeated tags, and a body that its decoder does not consume exactly.
//
// To add a section: give it a tag here, implement has<X>Section (write it?), put<X>Section (the body only) and
// get<X>Section (reads and validates exactly the body) in io/grid_section_<x>.cpp, and list it in sectionCodecs()
// in io/grid_file.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "io/byte_codec.h"
#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox {

enum class SectionTag : uint32_t {
  Textures = 1,
  SolidTextures = 2,
  Brick = 3,
  CameraSpan = 4,
  Distances = 5,  // grid file version 4 (keys as a flat array) and 5 (keys as runs)
  Fractions = 6,  // grid file version 4
};

// What a section's reader knows beyond its bytes: the file's version (a section's layout may change with it) and
// the reader's progress, to be asked with the fraction of the file read at that point (monotone; false cancels).
struct SectionContext {
  uint32_t version;
  std::function<bool(double)> progress;  // empty when nobody asks
  size_t fileSize;                       // the bytes the fraction is of
};

struct SectionCodec {
  SectionTag tag;
  const char* name;  // for error messages
  bool (*has)(const Scene&, const Grid&);
  // `memo`: the writer's scratch for this section, empty at its first call and kept across the passes of one write
  // (writeGridFile encodes the payload three times, each section twice): what a section derives from the grid (the
  // Distances section's runs) is derived once.
  void (*put)(ByteWriter&, const Scene&, const Grid&, std::string& memo);
  void (*get)(ByteReader&, Scene&, Grid&, const SectionContext&);
};

// Textures (io/grid_section_textures.cpp): image textures, material texture indices, triangle texture coordinates.
bool hasTexturesSection(const Scene& scene, const Grid& grid);
void putTexturesSection(ByteWriter& w, const Scene& scene, const Grid& grid, std::string& memo);
void getTexturesSection(ByteReader& r, Scene& scene, Grid& grid, const SectionContext& context);

// SolidTextures (io/grid_section_solid_textures.cpp): the course's Checkerboard, Noise, Marble and Wood materials.
bool hasSolidTexturesSection(const Scene& scene, const Grid& grid);
void putSolidTexturesSection(ByteWriter& w, const Scene& scene, const Grid& grid, std::string& memo);
void getSolidTexturesSection(ByteReader& r, Scene& scene, Grid& grid, const SectionContext& context);

// CameraSpan (io/grid_section_camera.cpp): the side of the image a camera's angle or size spans, when not the height.
bool hasCameraSpanSection(const Scene& scene, const Grid& grid);
void putCameraSpanSection(ByteWriter& w, const Scene& scene, const Grid& grid, std::string& memo);
void getCameraSpanSection(ByteReader& r, Scene& scene, Grid& grid, const SectionContext& context);

// Distances (io/grid_section_distances.cpp): the --sdf band's cell keys and signed distances; written in version 5's
// layout, read in 4's too.
bool hasDistancesSection(const Scene& scene, const Grid& grid);
void putDistancesSection(ByteWriter& w, const Scene& scene, const Grid& grid, std::string& memo);
void getDistancesSection(ByteReader& r, Scene& scene, Grid& grid, const SectionContext& context);

// Fractions (io/grid_section_fractions.cpp): --fraction's volume fraction of each occupied cell.
bool hasFractionsSection(const Scene& scene, const Grid& grid);
void putFractionsSection(ByteWriter& w, const Scene& scene, const Grid& grid, std::string& memo);
void getFractionsSection(ByteReader& r, Scene& scene, Grid& grid, const SectionContext& context);

}  // namespace vox
