// Optional parts of a grid file (docs/grid-format.md "Sections"), each a tagged section after the solid runs:
// u32 tag, u64 size, then `size` bytes of body. A section is written only when it has content; a reader refuses
// unknown and repeated tags, and a body that its decoder does not consume exactly.
//
// To add a section: give it a tag here, implement has<X>Section (write it?), put<X>Section (the body only) and
// get<X>Section (reads and validates exactly the body) in io/grid_section_<x>.cpp, and list it in sectionCodecs()
// in io/grid_file.cpp.
#pragma once

#include <cstdint>

#include "io/byte_codec.h"
#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox {

enum class SectionTag : uint32_t {
  Textures = 1,
  SolidTextures = 2,
  Brick = 3,
  CameraSpan = 4,
  Distances = 5,  // grid file version 4
  Fractions = 6,  // grid file version 4
};

struct SectionCodec {
  SectionTag tag;
  const char* name;  // for error messages
  bool (*has)(const Scene&, const Grid&);
  void (*put)(ByteWriter&, const Scene&, const Grid&);
  void (*get)(ByteReader&, Scene&, Grid&);
};

// Textures (io/grid_section_textures.cpp): image textures, material texture indices, triangle texture coordinates.
bool hasTexturesSection(const Scene& scene, const Grid& grid);
void putTexturesSection(ByteWriter& w, const Scene& scene, const Grid& grid);
void getTexturesSection(ByteReader& r, Scene& scene, Grid& grid);

// SolidTextures (io/grid_section_solid_textures.cpp): the course's Checkerboard, Noise, Marble and Wood materials.
bool hasSolidTexturesSection(const Scene& scene, const Grid& grid);
void putSolidTexturesSection(ByteWriter& w, const Scene& scene, const Grid& grid);
void getSolidTexturesSection(ByteReader& r, Scene& scene, Grid& grid);

// CameraSpan (io/grid_section_camera.cpp): the side of the image a camera's angle or size spans, when not the height.
bool hasCameraSpanSection(const Scene& scene, const Grid& grid);
void putCameraSpanSection(ByteWriter& w, const Scene& scene, const Grid& grid);
void getCameraSpanSection(ByteReader& r, Scene& scene, Grid& grid);

// Distances (io/grid_section_distances.cpp): the --sdf band's cell keys and signed distances.
bool hasDistancesSection(const Scene& scene, const Grid& grid);
void putDistancesSection(ByteWriter& w, const Scene& scene, const Grid& grid);
void getDistancesSection(ByteReader& r, Scene& scene, Grid& grid);

// Fractions (io/grid_section_fractions.cpp): --fraction's volume fraction of each occupied cell.
bool hasFractionsSection(const Scene& scene, const Grid& grid);
void putFractionsSection(ByteWriter& w, const Scene& scene, const Grid& grid);
void getFractionsSection(ByteReader& r, Scene& scene, Grid& grid);

}  // namespace vox
