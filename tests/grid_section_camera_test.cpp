// The CameraSpan section of grid files (io/grid_section_camera.cpp): the course's cameras keep the side their angle or
// size spans through a grid file (a wide image frames the same before and after), every other camera writes the
// bytes it wrote before, and every truncation, bit flip and hostile body of the section is refused.
#include <gtest/gtest.h>

#include <cstring>

#include "grid_file_util.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"
#include "vox/trace/accel.h"
#include "vox/trace/render.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::resealed;
using testing::smallGrid;

constexpr size_t kSectionBytes = 4 + 8 + 1;  // tag, size, span

Scene cameraScene(CameraKind kind) {
  Scene s = testing::randomScene(7, 6, 2);
  Camera c;
  c.kind = kind;
  c.center = {0.5, 0.6, 3};
  c.direction = {0, -0.1, -1};
  c.fovDegrees = 40;
  c.orthoHeight = 1.5;
  c.span = CameraSpan::LongerSide;
  s.camera = c;
  return s;
}

std::string section(uint8_t span, uint64_t size = 1) {
  std::string out(kSectionBytes, '\0');
  const uint32_t tag = 4;
  std::memcpy(&out[0], &tag, 4);
  std::memcpy(&out[4], &size, 8);
  out[12] = char(span);
  return out;
}

TEST(GridSectionCamera, CourseCamerasKeepTheirSpanAndFraming) {
  for (CameraKind kind : {CameraKind::Perspective, CameraKind::Orthographic}) {
    const Scene s = cameraScene(kind);
    const Grid g = smallGrid(s, 3);
    const std::string bytes = encodeGridFile(s, g);
    EXPECT_EQ(bytes.substr(bytes.size() - kSectionBytes), section(1));  // the last section written
    const GridFile f = decodeGridFile(bytes, "t.vgrid");
    ASSERT_TRUE(f.scene.camera);
    EXPECT_EQ(f.scene.camera->span, CameraSpan::LongerSide);
    EXPECT_EQ(encodeGridFile(f.scene, f.grid), bytes);
    // A wide image frames the same from the file as from the scene, and not as the vertical convention does.
    RenderOptions ro;
    ro.width = 24, ro.height = 12;
    ro.camera = *s.camera;
    const Image before = traceImage(s, buildAccel(s, g, AccelKind::Grid), ro);
    ro.camera = *f.scene.camera;
    EXPECT_EQ(traceImage(f.scene, buildAccel(f.scene, f.grid, AccelKind::Grid), ro).pixels, before.pixels);
    ro.camera.span = CameraSpan::Height;
    EXPECT_NE(traceImage(f.scene, buildAccel(f.scene, f.grid, AccelKind::Grid), ro).pixels, before.pixels);
    // The vertical convention (flags, glTF) and no camera at all write no section: the bytes of before.
    Scene height = s;
    height.camera->span = CameraSpan::Height;
    EXPECT_EQ(encodeGridFile(height, g).size() + kSectionBytes, bytes.size());
    EXPECT_EQ(encodeGridFile(height, g).substr(32), bytes.substr(32, bytes.size() - 32 - kSectionBytes));
    EXPECT_EQ(decodeGridFile(encodeGridFile(height, g), "h.vgrid").scene.camera->span, CameraSpan::Height);
  }
}

TEST(GridSectionCamera, EveryTruncationAndBitFlipIsRefused) {
  const Scene s = cameraScene(CameraKind::Perspective);
  const std::string bytes = encodeGridFile(s, smallGrid(s, 3));
  for (size_t n = bytes.size() - kSectionBytes; n < bytes.size(); ++n)
    EXPECT_THROW(decodeGridFile(bytes.substr(0, n), "cut.vgrid"), InputError) << n;
  for (size_t bit = (bytes.size() - kSectionBytes) * 8; bit < bytes.size() * 8; ++bit) {
    std::string flipped = bytes;
    flipped[bit / 8] = char(flipped[bit / 8] ^ (1 << (bit % 8)));
    EXPECT_THROW(decodeGridFile(flipped, "flip.vgrid"), InputError) << "bit " << bit;
  }
}

TEST(GridSectionCamera, HostileBodiesWithAValidChecksumAreRefused) {
  const Scene s = cameraScene(CameraKind::Perspective);
  const Grid g = smallGrid(s, 3);
  const std::string bytes = encodeGridFile(s, g);
  const std::string head = bytes.substr(0, bytes.size() - kSectionBytes);
  const auto refused = [](const std::string& m, const char* what) {
    try {
      decodeGridFile(resealed(m), "hostile.vgrid");
      ADD_FAILURE() << what << ": accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("hostile.vgrid"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(head + section(0), "unknown camera span 0");  // the default is never written
  refused(head + section(2), "unknown camera span 2");
  refused(head + section(255), "unknown camera span 255");
  refused(head + section(1) + section(1), "repeated camera span section");
  refused(head + section(1, 2) + std::string(1, '\0'), "camera span section does not match its size");
  Scene none = s;
  none.camera.reset();
  refused(encodeGridFile(none, g) + section(1), "camera span section without a camera");
  EXPECT_NO_THROW(decodeGridFile(resealed(head + section(1)), "ok.vgrid"));
}

}  // namespace
}  // namespace vox
