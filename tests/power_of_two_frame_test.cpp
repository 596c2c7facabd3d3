// The numeric domain of distances, signs and fractions (issue 45, defects 1, 9, 10, 11; docs/limits.md "Numeric
// domain"): a scene's answers at scale 2^k equal its answers at scale 1 times 2^k, bit for bit, from 2^-1000 to
// 2^1000; what lies outside is refused with one line; the writers never write a grid a reader refuses.
#include "vox/core/power_of_two_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/export/npz_writer.h"
#include "vox/io/grid_file.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

// Everything the Python calls of the issue compute for one scene: voxelize(..., resolution=8, sdf=3), the dense
// field (libvox.sdf), Grid.distance at every cell centre, and the volume fractions.
struct Answers {
  Grid grid;
  std::vector<CellRun> solid, windingSolid;  // the flood fill's and the winding number's
  std::vector<double> dense, atCentres, closest, fractions;
  std::vector<int64_t> primitives;
};

Answers answersFor(const Scene& scene) {
  Answers a;
  VoxelizeOptions vo;
  vo.resolution = 8;
  vo = withCubicCells(scene, vo);
  a.grid = voxelizeScene(scene, vo);
  SdfOptions so;
  so.halfWidth = 3;
  storeSignedDistances(a.grid, scene, so, false);
  Grid filled = a.grid;
  fillSolid(filled, scene);
  a.solid = filled.solidRuns;
  Grid winding = a.grid;
  fillSolid(winding, scene, fillForFractions({}));
  a.windingSolid = winding.solidRuns;
  a.dense.resize(filled.cellCount());
  denseSignedDistances(filled, scene, a.dense, {1, filled.dims[0], uint64_t(filled.dims[0]) * filled.dims[1]});
  std::vector<double> points;
  for (uint64_t key = 0; key < filled.cellCount(); ++key) {
    const Vec3 c = cellCentre(filled, key);
    points.insert(points.end(), {c.x, c.y, c.z});
  }
  a.atCentres.resize(filled.cellCount());
  a.primitives.resize(filled.cellCount());
  a.closest.resize(points.size());
  pointDistances(scene, points, true, {a.atCentres, a.primitives, a.closest});
  a.fractions = volumeFractions(a.grid, scene);
  return a;
}

// The cube [offset, offset + 1]^3 scaled by 2^k (the scaling exact: every coordinate a power of two times it).
Scene cube(double offset, int k) { return testing::boxScene(std::ldexp(offset, k), std::ldexp(offset + 1, k)); }

void expectScaled(const std::vector<double>& got, const std::vector<double>& unit, int k, const char* what) {
  ASSERT_EQ(got.size(), unit.size()) << what;
  for (size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], std::ldexp(unit[i], k)) << what << " " << i << " k " << k;
}

void expectAnswersScaled(const Answers& got, const Answers& unit, int k) {
  for (int a = 0; a < 3; ++a) {
    ASSERT_EQ(got.grid.bounds.lo[a], std::ldexp(unit.grid.bounds.lo[a], k)) << k;
    ASSERT_EQ(got.grid.bounds.hi[a], std::ldexp(unit.grid.bounds.hi[a], k)) << k;
  }
  ASSERT_EQ(got.grid.dims, unit.grid.dims) << k;
  ASSERT_EQ(std::vector<uint64_t>(got.grid.cellKeys.begin(), got.grid.cellKeys.end()),
            std::vector<uint64_t>(unit.grid.cellKeys.begin(), unit.grid.cellKeys.end()))
      << k;
  const auto runs = [](const std::vector<CellRun>& r) {
    std::vector<uint64_t> out;
    for (const CellRun& c : r) out.insert(out.end(), {c.first, c.count});
    return out;
  };
  ASSERT_FALSE(unit.solid.empty());
  ASSERT_EQ(runs(got.solid), runs(unit.solid)) << k;
  ASSERT_EQ(runs(got.windingSolid), runs(unit.windingSolid)) << k;  // at 2^400 it once filled nothing
  ASSERT_EQ(got.grid.sdfKeys, unit.grid.sdfKeys) << k;
  expectScaled(got.grid.sdfValues, unit.grid.sdfValues, k, "band");
  expectScaled(got.dense, unit.dense, k, "dense");
  expectScaled(got.atCentres, unit.atCentres, k, "Grid.distance");
  expectScaled(got.closest, unit.closest, k, "closest points");
  ASSERT_EQ(got.primitives, unit.primitives) << k;
  ASSERT_EQ(got.fractions, unit.fractions) << k;  // dimensionless: equal, not scaled
}

TEST(PowerOfTwoFrame, CubeAnswersScaleBitForBitFrom2PowMinus1000To2Pow1000) {
  for (const double offset : {0.0, -0.5, 1e6}) {
    const Answers unit = answersFor(cube(offset, 0));
    // The band holds the surface, equals the dense field there, and the fractions add up to the cube.
    ASSERT_FALSE(unit.grid.sdfKeys.empty());
    for (size_t b = 0; b < unit.grid.sdfKeys.size(); ++b)
      ASSERT_EQ(unit.grid.sdfValues[b], unit.dense[unit.grid.sdfKeys[b]]) << offset;
    for (int k = -1000; k <= 1000; k += 50) expectAnswersScaled(answersFor(cube(offset, k)), unit, k);
  }
}

// Defect 1: a cube of side 1.3e154 (and more) squared its reach to +infinity, and the band took every cell of its
// edge tiles, 17 in an 8-deep grid among them, with infinite values.
TEST(PowerOfTwoFrame, HugeCubeBandStaysInsideTheGridAndWrites) {
  for (const double side : {1.3e154, 1e200, 1e300}) {
    const Scene scene = testing::boxScene(0, side);
    VoxelizeOptions vo;
    vo.resolution = 8;
    vo = withCubicCells(scene, vo);
    Grid g = voxelizeScene(scene, vo);
    SdfOptions so;
    so.halfWidth = 3;
    storeSignedDistances(g, scene, so, false);
    ASSERT_FALSE(g.sdfKeys.empty());
    for (size_t b = 0; b < g.sdfKeys.size(); ++b) {
      ASSERT_LT(g.sdfKeys[b], g.cellCount());
      if (b > 0) {
        ASSERT_LT(g.sdfKeys[b - 1], g.sdfKeys[b]);
      }
      ASSERT_TRUE(std::isfinite(g.sdfValues[b])) << side;
    }
    EXPECT_NO_THROW(checkGridBeforeWrite(g, "cube"));
    std::ostringstream npz;
    EXPECT_GT(writeNpz(npz, g), 0u);
    const GridFile back = decodeGridFile(encodeGridFile(scene, g), "cube");
    EXPECT_EQ(back.grid.sdfKeys, g.sdfKeys);
    EXPECT_EQ(back.grid.sdfValues, g.sdfValues);
  }
}

// The writers check the band and the fractions before writing: a key past the grid, a repeated key, a value that
// is not finite, a fraction outside [0, 1] are refused with one line, never written out of bounds.
TEST(PowerOfTwoFrame, WritersRefuseGridsTheReaderWouldRefuse) {
  const Scene scene = cube(0, 0);
  VoxelizeOptions vo;
  vo.dims = std::array<uint32_t, 3>{8, 8, 8};
  const Grid good = voxelizeScene(scene, vo);
  const testing::ScratchDir dir("frame_writers");
  const auto refused = [&](const Grid& g) {
    for (int writer = 0; writer < 3; ++writer) {
      try {
        std::ostringstream out;
        if (writer == 0) writeNpz(out, g);
        if (writer == 1) writeGridFile(dir.file("g.vgrid"), scene, g);
        if (writer == 2) checkGridBeforeWrite(g, "g");
        ADD_FAILURE() << "writer " << writer << " wrote it";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("not written"), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      }
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));  // nothing written, no temporary left
  };
  Grid g = good;
  g.sdfHalfWidth = 3;
  g.sdfKeys = {5, 17 * 64, 17 * 64};  // past the 512 cells, and repeated: issue 45's band
  g.sdfValues = {1, INFINITY, -INFINITY};
  refused(g);
  g.sdfKeys = {5, 6, 6};
  g.sdfValues = {1, 2, 3};
  refused(g);
  g.sdfKeys = {5, 6, 7};
  g.sdfValues = {1, NAN, 3};
  refused(g);
  g = good;
  g.fractions.assign(g.cellKeys.size(), 0.5);
  g.fractions[1] = NAN;
  refused(g);
}

// Defect 9 and the offsets: cells narrower than the coordinates' spacing (a unit cube moved to 1e16: its cell
// boundaries coincide) are refused with one line giving the spacing, never answered with NaN.
TEST(PowerOfTwoFrame, CoincidingCellBoundariesAreRefused) {
  const Scene scene = testing::boxScene(1e16, 1e16 + 16);
  VoxelizeOptions vo;
  vo.bounds = Box{{1e16, 1e16, 1e16}, {1e16 + 16, 1e16 + 16, 1e16 + 16}};
  vo.dims = std::array<uint32_t, 3>{64, 64, 64};
  Grid g = voxelizeScene(scene, vo);
  for (int call = 0; call < 2; ++call) {
    try {
      if (call == 0) volumeFractions(g, scene);
      SdfOptions so;
      if (call == 1) storeSignedDistances(g, scene, so, false);
      ADD_FAILURE() << "call " << call << " answered";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("coincide"), std::string::npos) << m;
      EXPECT_NE(m.find("spacing 2 "), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
}

// Defect 11: squared distances of far points overflowed to +infinity. Points within 2^500 of the scene's magnitude
// get finite, right distances; farther ones are refused with one line naming the point and the range.
TEST(PowerOfTwoFrame, FarPointsAreRightOrRefused) {
  const Scene scene = cube(-0.5, 0);  // [-0.5, 0.5]^3: magnitude 0.5, frame 2^-1
  std::vector<double> d(2), closest(6);
  std::vector<int64_t> prim(2);
  const double far = std::ldexp(1.0, 498);
  const std::vector<double> points{far, 0.25, 0.125, 0.25, -far, 0.125};
  pointDistances(scene, points, true, {d, prim, closest});
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(d[i], far) << i;  // far - 0.5, rounded
    EXPECT_GE(prim[i], 0);
    for (int a = 0; a < 3; ++a) EXPECT_LE(std::fabs(closest[3 * i + a]), 0.5) << i;
  }
  for (const double x : {1e300, -1e160, 1.2e307}) {
    const std::vector<double> p{0, x, 0};
    try {
      pointDistances(scene, p, false, {d, prim, closest});
      ADD_FAILURE() << x;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind("points[0, 1] is ", 0), 0u) << m;
      EXPECT_NE(m.find("within +-1.636695303948071e+150"), std::string::npos) << m;  // 2^(500-1)
    }
  }
  // A dense field over bounds of +-1e300 about a unit cube: refused, naming the range, not +infinity.
  VoxelizeOptions vo;
  vo.bounds = Box{{-1e300, -1e300, -1e300}, {1e300, 1e300, 1e300}};
  vo.dims = std::array<uint32_t, 3>{4, 4, 4};
  Grid g = voxelizeScene(scene, vo);
  fillSolid(g, scene);
  std::vector<double> field(g.cellCount());
  try {
    denseSignedDistances(g, scene, field, {1, 4, 16});
    ADD_FAILURE() << "answered";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sdf: cell centres reach 7.5e+299 (bounds 1e+300)"), std::string::npos)
        << e.what();
  }
}

// Bounds of +-1e300 in one cell: its centre is on the scene, so the distance there is answered.
TEST(PowerOfTwoFrame, OneHugeCellAboutTheSceneIsAnswered) {
  const Scene scene = cube(-0.5, 0);
  VoxelizeOptions vo;
  vo.bounds = Box{{-1e300, -1e300, -1e300}, {1e300, 1e300, 1e300}};
  vo.dims = std::array<uint32_t, 3>{1, 1, 1};
  Grid g = voxelizeScene(scene, vo);
  fillSolid(g, scene);
  std::vector<double> field(1);
  denseSignedDistances(g, scene, field, {1, 1, 1});
  EXPECT_EQ(field[0], -0.5);
}

TEST(PowerOfTwoFrame, CoordinatesBeyond2Pow1020AreRefused) {
  const Scene scene = testing::boxScene(0, 1.5e307);
  VoxelizeOptions vo;
  vo.dims = std::array<uint32_t, 3>{4, 4, 4};
  Grid g = voxelizeScene(scene, vo);
  SdfOptions so;
  try {
    storeSignedDistances(g, scene, so, false);
    ADD_FAILURE() << "answered";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is beyond +-1.1235582092889474e+307 (2^1020)"), std::string::npos)
        << e.what();
  }
}

// vox-voxelize's route (storeSignedDistancesInPlace, which scales the scene's own triangles into the frame and back
// instead of copying them) equals the copying one bit for bit, and gives the scene back as it was: scaled up, not
// scaled, scaled down, and with a coordinate the way back would round (copied instead); also when it throws.
TEST(PowerOfTwoFrame, InPlaceSignedDistancesEqualTheCopyAndGiveTheSceneBack) {
  std::vector<std::pair<Scene, std::string>> scenes;
  for (const int k : {-1000, -3, 0, 5, 1000}) scenes.push_back({cube(-0.5, k), "cube 2^" + std::to_string(k)});
  scenes.push_back({cube(0.5, 0), "cube in its own frame"});
  scenes.push_back({loadScene(testing::seed("meshes/bun_zipper.ply")), "bunny"});
  Scene subnormal = cube(0, 1000);  // 2^-1074 scaled by 2^-1000 is no double: the way back would give 0
  subnormal.triangles.push_back(
      {{Vec3{0, 0, 0}, Vec3{std::ldexp(1.0, -1074), 0, 0}, Vec3{0, std::ldexp(1.0, 999), 0}}});
  scenes.push_back({subnormal, "a subnormal coordinate at 2^1000"});
  const auto coordinates = [](const Scene& s) {
    std::vector<double> out;
    for (const Triangle& t : s.triangles)
      for (const Vec3& v : t.v) out.insert(out.end(), {v.x, v.y, v.z});
    return out;
  };
  for (auto& [scene, what] : scenes) {
    VoxelizeOptions vo;
    vo.resolution = 24;
    vo = withCubicCells(scene, vo);
    const Grid plain = voxelizeScene(scene, vo);
    SdfOptions so;
    so.halfWidth = 3;
    Grid copied = plain, inPlace = plain;
    storeSignedDistances(copied, scene, so, false);
    const std::vector<double> before = coordinates(scene);
    storeSignedDistancesInPlace(inPlace, scene, so);
    ASSERT_FALSE(copied.sdfKeys.empty()) << what;
    ASSERT_EQ(inPlace.sdfKeys, copied.sdfKeys) << what;
    for (size_t b = 0; b < copied.sdfValues.size(); ++b)  // bitwise: -0.0 is not +0.0
      ASSERT_EQ(std::signbit(inPlace.sdfValues[b]), std::signbit(copied.sdfValues[b])) << what << " " << b;
    ASSERT_EQ(inPlace.sdfValues, copied.sdfValues) << what;
    for (int a = 0; a < 3; ++a) ASSERT_EQ(inPlace.bounds.lo[a], plain.bounds.lo[a]) << what;
    const std::vector<double> after = coordinates(scene);
    ASSERT_EQ(std::memcmp(after.data(), before.data(), before.size() * sizeof(double)), 0) << what;
    Grid cancelled = plain;
    so.progress = [](double) { return false; };
    EXPECT_THROW(storeSignedDistancesInPlace(cancelled, scene, so), Error) << what;
    const std::vector<double> afterThrow = coordinates(scene);
    ASSERT_EQ(std::memcmp(afterThrow.data(), before.data(), before.size() * sizeof(double)), 0) << what;
  }
}

}  // namespace
}  // namespace vox
