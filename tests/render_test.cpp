// Rendering: accel grid and accel none give bit-identical images on every assignment 5 and 6 seed scene and on
// random scenes and cameras (issue 3, test 1); the camera convention of DESIGN.md; modes; image writing.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "seed_cases.h"
#include "render_util.h"
#include "test_util.h"
#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/io/image_io.h"
#include "vox/import/import.h"
#include "vox/trace/render.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::differingPixels;
using testing::renderWith;
using testing::voxelizeWith;

int nonBackgroundPixels(const Image& image, const Vec3& background) {
  int count = 0;
  for (size_t p = 0; p < image.pixels.size(); p += 3)
    count += image.pixels[p] != float(background.x) || image.pixels[p + 1] != float(background.y) ||
             image.pixels[p + 2] != float(background.z);
  return count;
}

using testing::kSeedCases;
using testing::SeedCase;

class SeedScene : public ::testing::TestWithParam<SeedCase> {};

TEST_P(SeedScene, GridAndBruteForceImagesAreIdentical) {
  const SeedCase& c = GetParam();
  const std::string path = std::string(VOX_SEED_DIR) + "/6837/scenes/" + c.file;
  const Scene scene = loadScene(path);
  RenderOptions ro;
  // Small images keep brute force on the 40k bunny affordable; 6_18 is the wide one.
  const bool big = scene.triangles.size() > 10000;
  ro.width = big ? 24 : 48;
  ro.height = std::string(c.file).find("6.837") != std::string::npos ? ro.width / 2 : ro.width;
  ro.camera = scene.camera ? *scene.camera : defaultCamera(*sceneBounds(scene));
  for (OverlapMethod m : {OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox, OverlapMethod::Center}) {
    const Grid grid = voxelizeWith(scene, c.dims, m);
    RenderStats gs;
    const Image g = renderWith(scene, grid, AccelKind::Grid, ro, &gs);
    const Image n = renderWith(scene, grid, AccelKind::None, ro);
    const int differ = differingPixels(g, n);
    if (m == OverlapMethod::Center) {
      RecordProperty(std::string("center_differing_pixels_") + c.file, differ);
      if (differ)
        std::printf("[ info ] %s center grid: %d of %u pixels differ\n", c.file, differ, ro.width * ro.height);
    } else {
      EXPECT_EQ(differ, 0) << c.file << " " << methodName(m);
    }
    if (m == OverlapMethod::Exact) {
      EXPECT_GT(nonBackgroundPixels(n, scene.background), int(ro.width * ro.height) / 50) << "nothing visible";
      EXPECT_GT(gs.trace.cells, 0u);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Assignments5And6, SeedScene, ::testing::ValuesIn(kSeedCases),
                         [](const ::testing::TestParamInfo<SeedCase>& info) {
                           std::string name = std::to_string(info.index) + "_" + info.param.file;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

TEST(RenderGridVsBruteForce, RandomScenesAndCamerasInsideAndOutside) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_int_distribution<uint32_t> dim(1, 16);
  int checked = 0;
  for (uint32_t seed = 0; seed < 8; ++seed) {
    Scene scene = testing::randomScene(200 + seed, 60, 4, -1, 2);
    if (seed % 2) scene.planes.push_back(Plane{normalize(Vec3{0, 1, 0.1}), -0.9, 0});
    scene.lights.push_back(Light{LightKind::Point, {}, {0.5, 3, 2}, {1, 1, 1}, {1, 0.1, 0}});
    scene.lights.push_back(Light{LightKind::Directional, {-0.3, -1, -0.2}, {}, {0.5, 0.5, 0.5}, {1, 0, 0}});
    scene.materials[0].specular = {0.5, 0.5, 0.5};
    scene.materials[0].exponent = 20;
    const Box b = *sceneBounds(scene);
    const Vec3 centre = (b.lo + b.hi) * 0.5;
    for (int cam = 0; cam < 3; ++cam) {
      RenderOptions ro;
      ro.width = 40;
      ro.height = 30;
      ro.samples = cam == 2 ? 4 : 1;
      ro.mode = cam == 1 ? RenderMode::Normals : RenderMode::Shade;
      // Outside looking in, inside the scene (camera inside the grid), orthographic.
      ro.camera.center = cam == 1 ? centre + Vec3{0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)}
                                  : centre + Vec3{4 * u(rng) - 2, 4 * u(rng) - 2, 5};
      ro.camera.direction = cam == 1 ? Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} : centre - ro.camera.center;
      ro.camera.kind = cam == 2 ? CameraKind::Orthographic : CameraKind::Perspective;
      ro.camera.fovDegrees = 50;
      ro.camera.orthoHeight = 2.5;
      for (OverlapMethod m : {OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox}) {
        const Grid grid = voxelizeWith(scene, {dim(rng), dim(rng), dim(rng)}, m);
        EXPECT_EQ(
            differingPixels(renderWith(scene, grid, AccelKind::Grid, ro), renderWith(scene, grid, AccelKind::None, ro)),
            0)
            << "seed " << seed << " camera " << cam << " " << methodName(m);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 8 * 3 * 3);
}

TEST(Camera, PrimaryRaysFollowTheConvention) {
  Camera cam;
  cam.center = {1, 2, 3};
  cam.direction = {0, 0, -2};
  cam.up = {0, 3, 0};
  cam.fovDegrees = 90;
  // 4x2 image: pixel (0, 0) is top-left: u = (2*0.5/4 - 1) * tan(45) * 2 = -1.5, v = (1 - 2*0.5/2) * 1 = 0.5.
  Ray r = primaryRay(cam, 4, 2, 0.5, 0.5);
  EXPECT_EQ(r.origin.x, 1);
  EXPECT_NEAR(r.direction.x, -1.5, 1e-15);  // right = direction x up = -z x y = +x
  EXPECT_NEAR(r.direction.y, 0.5, 1e-15);
  EXPECT_NEAR(r.direction.z, -1, 1e-15);
  // Bottom-right pixel of the same image.
  r = primaryRay(cam, 4, 2, 3.5, 1.5);
  EXPECT_NEAR(r.direction.x, 1.5, 1e-15);
  EXPECT_NEAR(r.direction.y, -0.5, 1e-15);
  // Orthographic: parallel rays from the image plane of height orthoHeight.
  cam.kind = CameraKind::Orthographic;
  cam.orthoHeight = 4;
  r = primaryRay(cam, 4, 2, 0.5, 0.5);
  EXPECT_NEAR(r.origin.x, 1 - 3, 1e-15);  // u = -0.75 * (4/2) * 2
  EXPECT_NEAR(r.origin.y, 2 + 1, 1e-15);  // v = 0.5 * 2
  EXPECT_NEAR(r.direction.z, -1, 1e-15);
  cam.up = {0, 0, 1};  // parallel to the direction
  EXPECT_THROW(primaryRay(cam, 4, 2, 0.5, 0.5), UsageError);
}

// The course's cameras (CameraSpan::LongerSide) spread the angle or size over the longer side: across the width of a
// wide image, with the height getting height / width of it; on square and tall images exactly as the vertical
// convention (one pixel either side of square: 5x4, 4x4, 4x5).
TEST(Camera, CourseCamerasSpanTheLongerSide) {
  for (CameraKind kind : {CameraKind::Perspective, CameraKind::Orthographic}) {
    Camera height;
    height.kind = kind;
    height.center = {1, 2, 3};
    height.direction = {0, 0, -2};
    height.up = {0, 3, 0};
    height.fovDegrees = 90;  // tan(45) = 1
    height.orthoHeight = 2;  // half extent 1
    Camera course = height;
    course.span = CameraSpan::LongerSide;
    // The image plane point of a ray: its direction (perspective) or its origin's offset (orthographic).
    auto plane = [&](const Camera& c, uint32_t w, uint32_t h, double px, double py) {
      const Ray r = primaryRay(c, w, h, px, py);
      return kind == CameraKind::Perspective ? r.direction : r.origin - c.center;
    };
    // 400x200: the right edge at u = 1 (45 degrees, or half the size), the top edge at v = 0.5.
    EXPECT_NEAR(plane(course, 400, 200, 400, 100).x, 1, 1e-15) << int(kind);
    EXPECT_NEAR(plane(course, 400, 200, 200, 0).y, 0.5, 1e-15);
    EXPECT_NEAR(plane(height, 400, 200, 400, 100).x, 2, 1e-15);  // the vertical convention: twice as wide
    EXPECT_NEAR(plane(height, 400, 200, 200, 0).y, 1, 1e-15);
    // Pixel (i, j) of a W x H image looks through the course's screen point ((i + 0.5 - W/2) / max + 0.5, likewise
    // j) of its square [0,1]^2 (its glCanvas.C), that is u = 2 x - 1, v = 1 - 2 y with rows counted from the top.
    for (auto [w, h] : {std::pair<uint32_t, uint32_t>{5, 4}, {7, 3}, {400, 200}})
      for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
          const double m = std::max(w, h);
          const double x = (i + 0.5 - w / 2.0) / m + 0.5, y = (j + 0.5 - h / 2.0) / m + 0.5;
          const Vec3 p = plane(course, w, h, i + 0.5, j + 0.5);
          EXPECT_NEAR(p.x, 2 * x - 1, 1e-14) << w << "x" << h << " " << i << " " << j;
          EXPECT_NEAR(p.y, 1 - 2 * y, 1e-14) << w << "x" << h << " " << i << " " << j;
        }
    // Square and tall images: the same rays as the vertical convention, bit for bit.
    for (auto [w, h] : {std::pair<uint32_t, uint32_t>{4, 4}, {4, 5}, {1, 1}, {200, 400}})
      for (double py : {0.0, 0.5, h / 3.0, h - 0.5, double(h)})
        for (double px : {0.0, 0.5, w / 3.0, w - 0.5, double(w)}) {
          const Ray a = primaryRay(course, w, h, px, py), b = primaryRay(height, w, h, px, py);
          for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(a.origin[c], b.origin[c]) << w << "x" << h << " " << px << " " << py;
            EXPECT_EQ(a.direction[c], b.direction[c]) << w << "x" << h << " " << px << " " << py;
          }
        }
  }
}

Scene planeScene() {
  Scene scene;
  scene.materials.push_back({});
  scene.triangles.push_back(Triangle{{Vec3{-1, -1, 0}, Vec3{1, -1, 0}, Vec3{1, 1, 0}}});
  scene.triangles.push_back(Triangle{{Vec3{-1, -1, 0}, Vec3{1, 1, 0}, Vec3{-1, 1, 0}}});
  scene.background = {0.1, 0.2, 0.3};
  return scene;
}

TEST(RenderModes, DepthNormalsCountShade) {
  const Scene scene = planeScene();
  const Grid grid = voxelizeWith(scene, {4, 4, 1}, OverlapMethod::Exact);
  RenderOptions ro;
  ro.width = ro.height = 9;
  ro.camera.center = {0, 0, 5};
  ro.camera.direction = {0, 0, -1};
  ro.camera.fovDegrees = 60;  // the square fills the middle
  ro.mode = RenderMode::Depth;
  RenderStats st;
  const Image depth = renderWith(scene, grid, AccelKind::Grid, ro, &st);
  ASSERT_EQ(depth.channels, 1u);
  EXPECT_FLOAT_EQ(depth.at(4, 4)[0], 5.0f);  // centre: straight down
  EXPECT_EQ(depth.at(0, 0)[0], 0.0f);        // corner: misses (tan 30 * 5 = 2.9 > 1)
  const float off = depth.at(5, 4)[0];       // one pixel right: distance along the unit direction, > 5
  EXPECT_GT(off, 5.0f);
  EXPECT_NEAR(off, 5 * std::sqrt(1 + std::pow(2 * 1.0 / 9 * std::tan(M_PI / 6), 2)), 1e-5);
  EXPECT_FLOAT_EQ(float(st.depthMin), 5.0f);
  const Image grey = depthToGrey(depth);
  EXPECT_FLOAT_EQ(grey.at(4, 4)[0], 1.0f);
  EXPECT_EQ(grey.at(0, 0)[0], 0.0f);
  EXPECT_LT(grey.at(5, 3)[0], 1.0f);

  ro.mode = RenderMode::Normals;  // (n + 1) / 2 of the normal facing the viewer: +z -> (0.5, 0.5, 1)
  const Image normals = renderWith(scene, grid, AccelKind::Grid, ro);
  EXPECT_FLOAT_EQ(normals.at(4, 4)[2], 1.0f);
  EXPECT_FLOAT_EQ(normals.at(4, 4)[0], 0.5f);
  ro.camera.center = {0, 0, -5};  // from below: the normal turns to -z
  ro.camera.direction = {0, 0, 1};
  EXPECT_FLOAT_EQ(renderWith(scene, grid, AccelKind::Grid, ro).at(4, 4)[2], 0.0f);

  ro.mode = RenderMode::Count;
  const Image count = renderWith(scene, grid, AccelKind::Grid, ro, &st);
  EXPECT_GE(st.countMax, 1.0);
  EXPECT_EQ(count.channels, 3u);

  // Shade without lights, from below (the camera of the normals check): the square shows its back, black without
  // shadeBack as in the course; with it the headlight straight down the view gives diffuse 1 at the centre.
  ro.mode = RenderMode::Shade;
  EXPECT_FLOAT_EQ(renderWith(scene, grid, AccelKind::Grid, ro).at(4, 4)[0], 0.0f);
  ro.shadeBack = true;
  const Image shade = renderWith(scene, grid, AccelKind::Grid, ro);
  EXPECT_FLOAT_EQ(shade.at(4, 4)[0], 1.0f);
  EXPECT_FLOAT_EQ(shade.at(0, 0)[2], 0.3f);
}

TEST(RenderModes, ShadowRaysDarkenWhatIsBehindAnOccluder) {
  Scene scene = planeScene();
  // A small square above the middle of the floor, and a light straight above.
  scene.triangles.push_back(Triangle{{Vec3{-0.3, -0.3, 1}, Vec3{0.3, -0.3, 1}, Vec3{0.3, 0.3, 1}}});
  scene.triangles.push_back(Triangle{{Vec3{-0.3, -0.3, 1}, Vec3{0.3, 0.3, 1}, Vec3{-0.3, 0.3, 1}}});
  scene.lights.push_back(Light{LightKind::Directional, {0, 0, -1}, {}, {1, 1, 1}, {1, 0, 0}});
  const Grid grid = voxelizeWith(scene, {5, 5, 5}, OverlapMethod::Exact);
  RenderOptions ro;
  ro.width = ro.height = 21;
  ro.camera.center = {0, -6, 3};
  ro.camera.direction = Vec3{0, 0, 0.2} - ro.camera.center;
  ro.camera.fovDegrees = 30;
  RenderStats st;
  const Image img = renderWith(scene, grid, AccelKind::Grid, ro, &st);
  EXPECT_GT(st.trace.rays, uint64_t(ro.width) * ro.height);  // shadow rays were traced
  // Some floor pixels are in shadow (0) and some lit (1).
  int lit = 0, dark = 0;
  for (size_t p = 0; p < img.pixels.size(); p += 3) {
    lit += img.pixels[p] == 1.0f;
    dark += img.pixels[p] == 0.0f;
  }
  EXPECT_GT(lit, 10);
  EXPECT_GT(dark, 0);
  EXPECT_EQ(differingPixels(img, renderWith(scene, grid, AccelKind::None, ro)), 0);
}

TEST(RenderDeterminism, ThreadCountAndRepeatsDoNotChangeTheImage) {
  const Scene scene = testing::randomScene(9, 80, 4);
  const Grid grid = voxelizeWith(scene, {8, 8, 8}, OverlapMethod::Exact);
  RenderOptions ro;
  ro.width = 37;
  ro.height = 23;
  ro.samples = 5;
  ro.camera = defaultCamera(*sceneBounds(scene));
  Image one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = renderWith(scene, grid, AccelKind::Grid, ro);
  }
  EXPECT_EQ(differingPixels(one, renderWith(scene, grid, AccelKind::Grid, ro)), 0);
  ro.seed = 1;  // another jitter seed gives another (antialiased) image
  EXPECT_GT(differingPixels(one, renderWith(scene, grid, AccelKind::Grid, ro)), 0);
}

TEST(RenderModes, VoxelsDrawOccupiedCellsOnly) {
  Scene scene;
  scene.materials.push_back({});
  Sphere s;
  s.radius = 1;
  scene.spheres.push_back(s);
  scene.background = {0, 0, 0};
  const Grid grid = voxelizeWith(scene, {1, 1, 1}, OverlapMethod::Exact);
  RenderOptions ro;
  ro.width = ro.height = 20;
  ro.mode = RenderMode::Voxels;
  ro.camera.center = {0, 0, 3};
  ro.camera.direction = {0, 0, -1};
  ro.camera.kind = CameraKind::Orthographic;
  ro.camera.orthoHeight = 4;
  // A 1x1x1 grid fills the bounding box [-1, 1]^3: exactly the middle half of the image is drawn, as a square.
  const Image img = renderWith(scene, grid, AccelKind::Grid, ro);
  for (uint32_t y = 0; y < 20; ++y)
    for (uint32_t x = 0; x < 20; ++x) {
      const bool inside = x >= 5 && x < 15 && y >= 5 && y < 15;
      const float* p = img.at(x, y);
      EXPECT_EQ(p[0] + p[1] + p[2] > 0, inside) << x << " " << y;
    }
}

TEST(ImageIo, DepthIsOneFloatChannelNamedZ) {
  // Compositors (Blender, Nuke) and OpenImageIO's own conventions take a channel named Z as depth (issue 10).
  testing::ScratchDir dir("image_io_depth");
  Image img;
  img.width = 2;
  img.height = 2;
  img.channels = 1;
  img.pixels = {0, 1.5f, 1e-7f, 12345.678f};
  for (const char* name : {"d.exr", "d.tif"}) {
    SCOPED_TRACE(name);
    writeImage(dir.file(name), img);
    auto in = OIIO::ImageInput::open(dir.file(name));
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.nchannels, 1);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
    if (std::string(name) == "d.exr") {
      EXPECT_EQ(spec.channelnames[0], "Z");
      EXPECT_EQ(spec.z_channel, 0);
    }
    std::vector<float> px(4);
    ASSERT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, px.data()));
    EXPECT_EQ(px, img.pixels);
  }
}

TEST(ImageIo, WritesPngAndExrAndRefusesBadPaths) {
  testing::ScratchDir dir("image_io");
  Image img;
  img.width = 3;
  img.height = 2;
  img.channels = 3;
  img.pixels = {0, 0.5, 1, 2, -1, 0.25, 0.1, 0.2, 0.3, 1, 1, 1, 0, 0, 0, 0.75, 0.75, 0.75};
  writeImage(dir.file("a.png"), img);
  writeImage(dir.file("a.exr"), img);
  {
    auto in = OIIO::ImageInput::open(dir.file("a.png"));
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().width, 3);
    std::vector<unsigned char> px(18);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
    EXPECT_EQ(px[1], 128);  // 0.5 rounded
    EXPECT_EQ(px[3], 255);  // 2 clamped
    EXPECT_EQ(px[4], 0);    // -1 clamped
  }
  {
    auto in = OIIO::ImageInput::open(dir.file("a.exr"));
    ASSERT_TRUE(in);
    std::vector<float> px(18);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data()));
    EXPECT_EQ(px[3], 2.0f);  // floats kept as they are
    EXPECT_EQ(px[4], -1.0f);
  }
  EXPECT_FALSE(imageFormatSupported(dir.file("a.notaformat")));
  EXPECT_THROW(writeImage(dir.file("a.notaformat"), img), UsageError);
  EXPECT_THROW(writeImage(dir.file("missing/a.png"), img), OutputError);
  // Only the two images remain: no temporary files.
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 2u);
}

}  // namespace
}  // namespace vox
