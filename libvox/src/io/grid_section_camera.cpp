// The CameraSpan section of grid files (docs/grid-format.md "Sections"): which side of the image the camera's angle
// or size spans, written only for a camera whose span is not the default CameraSpan::Height (the course's cameras
// span the longer side), so files of every other camera keep their bytes.
//
// Body: u8 span (1 = CameraSpan::LongerSide). The section needs the camera of item 5, and the default value is
// never written, so a file has one encoding.
#include <string>

#include "io/grid_sections.h"

namespace vox {

bool hasCameraSpanSection(const Scene& scene, const Grid&) {
  return scene.camera && scene.camera->span != CameraSpan::Height;
}

void putCameraSpanSection(ByteWriter& w, const Scene& scene, const Grid&, std::string&) {
  w.put(uint8_t(scene.camera->span));
}

void getCameraSpanSection(ByteReader& r, Scene& scene, Grid&, const SectionContext&) {
  const uint8_t span = r.get<uint8_t>();
  if (!scene.camera) r.corrupt("camera span section without a camera");
  if (span != uint8_t(CameraSpan::LongerSide)) r.corrupt("unknown camera span " + std::to_string(span));
  scene.camera->span = CameraSpan(span);
}

}  // namespace vox
