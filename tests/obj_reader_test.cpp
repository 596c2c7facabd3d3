// Tests for the OBJ / MTL reader (obj_reader.cpp) and the OBJ importer built on it (import_obj.cpp): exact
// numbers, exact errors (file:line), indices, polygons of any size in linear time, continuations, CRLF, material
// libraries and where they may live.
#include "import/obj_reader.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/import/import.h"

namespace vox {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

std::string write(const ScratchDir& dir, const std::string& name, const std::string& content) {
  const std::string p = dir.file(name);
  std::ofstream(p, std::ios::binary) << content;
  return p;
}

// The message of the InputError that `f` throws ("" and a test failure when it throws none).
template <typename F>
std::string inputError(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}

// The error of reading `text` in one piece, which must also be the error of reading it a line per chunk
// (obj_chunks.h; obj_chunks_test.cpp compares every field of the readings).
std::string objError(const std::string& text) {
  const std::string whole = inputError([&] { parseObj(text, "a.obj"); });
  EXPECT_EQ(inputError([&] { parseObj(text, "a.obj", 1); }), whole) << "read a line per chunk";
  return whole;
}

uint64_t bits(double x) { return std::bit_cast<uint64_t>(x); }

TEST(ObjReader, NanInfinityAndGarbageAreRefusedNamingFileAndLine) {
  EXPECT_EQ(objError("v nan 5 5\n"), "a.obj:1: bad number 'nan'");
  EXPECT_EQ(objError("v 0 0 0\n\nv abc 0 0\n"), "a.obj:3: bad number 'abc'");
  EXPECT_EQ(objError("v 0 inf 0\n"), "a.obj:1: bad number 'inf'");
  EXPECT_EQ(objError("v 0 0 -infinity\n"), "a.obj:1: bad number '-infinity'");
  EXPECT_EQ(objError("v 1e999 0 0\n"), "a.obj:1: bad number '1e999'");
  EXPECT_EQ(objError("v 1.5x 0 0\n"), "a.obj:1: bad number '1.5x'");
  EXPECT_EQ(objError("v 0x10 0 0\n"), "a.obj:1: bad number '0x10'");
  EXPECT_EQ(objError("v 0 0 0 nan\n"), "a.obj:1: bad number 'nan'");  // a w or colour is checked too
  EXPECT_EQ(objError("v 0 0\n"), "a.obj:1: vertex needs 3 coordinates");
  // Control bytes are escaped and long words cut.
  EXPECT_EQ(objError("v \x01\x1b 0 0\n"), "a.obj:1: bad number '\\x01\\x1b'");
  EXPECT_EQ(objError("v " + std::string(100, 'q') + " 0 0\n"), "a.obj:1: bad number '" + std::string(40, 'q') + "...'");
  // A '+' sign and the other forms strtod takes are fine.
  const ObjData ok = parseObj("v +1 -2.5e-3 .5\n", "a.obj");
  ASSERT_EQ(ok.vertices.size(), 1u);
  EXPECT_EQ(ok.vertices[0].x, 1);
  EXPECT_EQ(ok.vertices[0].y, -2.5e-3);
  EXPECT_EQ(ok.vertices[0].z, 0.5);
}

TEST(ObjReader, ThroughTheImporterTheErrorNamesTheFile) {
  ScratchDir dir("objr");
  const std::string nan = write(dir, "nan.obj", "v nan 5 5\nv 0 0 0\nv 1 0 0\nf 1 2 3\n");
  EXPECT_EQ(inputError([&] { loadScene(nan); }), nan + ":1: bad number 'nan'");
  const std::string abc = write(dir, "abc.obj", "v 0 0 0\nv 1 0 0\nv abc 0 0\nf 1 2 3\n");
  EXPECT_EQ(inputError([&] { loadScene(abc); }), abc + ":3: bad number 'abc'");
}

TEST(ObjReader, IndexOverflowAndRangeAreRefused) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // 4294967298 = 2^32 + 2 once wrapped to vertex 2.
  EXPECT_EQ(objError(tri + "f 1 2 4294967298\n"), "a.obj:4: face index 4294967298 out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f 1 2 4294967295\n"), "a.obj:4: face index 4294967295 out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f 1 2 4\n"), "a.obj:4: face index 4 out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f 1 2 99999999999999999999999\n"),
            "a.obj:4: face index '99999999999999999999999' out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f 0 1 2\n"), "a.obj:4: face index 0 out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f -4 -2 -1\n"), "a.obj:4: face index -4 out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f -9223372036854775808 1 2\n"),
            "a.obj:4: face index -9223372036854775808 out of range (3 vertices)");
  EXPECT_EQ(objError(tri + "f 1 2 x\n"), "a.obj:4: bad face index 'x'");
  EXPECT_EQ(objError(tri + "f 1 2 3/x\n"), "a.obj:4: bad face index '3/x'");
  EXPECT_EQ(objError(tri + "f 1 2 3/1/1/1\n"), "a.obj:4: bad face index '3/1/1/1'");
  EXPECT_EQ(objError(tri + "f 1 2\n"), "a.obj:4: face needs at least 3 vertices");
  // A forward reference is checked against the whole file, and names its own line.
  EXPECT_EQ(objError("f 1 2 4\n" + tri), "a.obj:1: face index 4 out of range (3 vertices)");
}

TEST(ObjReader, NegativeAndForwardIndicesAndCornerForms) {
  const ObjData d = parseObj(
      "f 1 2 3\n"  // forward: the vertices follow
      "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
      "f -3 -2 -1\n"
      "v 0 0 1\nv 1 0 1\nv 0 1 1\n"
      "f -3/1 -2//7 -1/2/3\n"
      "f 1/+1 +2 3\n",
      "a.obj");
  ASSERT_EQ(d.triangles.size(), 4u);
  EXPECT_EQ(d.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(d.triangles[1], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(d.triangles[2], (std::array<uint32_t, 3>{3, 4, 5}));
  EXPECT_EQ(d.triangles[3], (std::array<uint32_t, 3>{0, 1, 2}));
}

TEST(ObjReader, PolygonsAreFanTriangulated) {
  const ObjData d = parseObj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 1 0\nf 1 2 3 4 5\n", "a.obj");
  ASSERT_EQ(d.triangles.size(), 3u);
  EXPECT_EQ(d.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(d.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(d.triangles[2], (std::array<uint32_t, 3>{0, 3, 4}));
}

TEST(ObjReader, AFaceOf300000IndicesLoadsInLinearTime) {
  // tinyobjloader's triangulation was quadratic: this face hung (hours). Not a timed test: the one big face must
  // load within ten times the time of the same vertices with its triangles written out as faces (linear: about one;
  // quadratic: thousands), each the fastest of three loads, so that a loaded machine slows both alike.
  constexpr int kCorners = 300000;
  ScratchDir dir("objr");
  std::string vertices;
  vertices.reserve(16 * kCorners);
  for (int i = 0; i < kCorners; ++i) {
    const double a = 2 * M_PI * i / kCorners;
    vertices += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  std::string bigFace = "f", fan;
  for (int i = 1; i <= kCorners; ++i) bigFace.append(" ").append(std::to_string(i));
  for (int i = 2; i < kCorners; ++i)
    fan.append("f 1 ").append(std::to_string(i)).append(" ").append(std::to_string(i + 1)).append("\n");
  const std::string bigPath = write(dir, "big.obj", vertices + bigFace + "\n");
  const std::string fanPath = write(dir, "fan.obj", vertices + fan);
  auto fastestLoad = [](const std::string& path) {
    double best = 1e9;
    for (int run = 0; run < 3; ++run) {
      const auto start = std::chrono::steady_clock::now();
      const Scene s = loadScene(path);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      EXPECT_EQ(s.triangles.size(), size_t{kCorners - 2});
    }
    return best;
  };
  const double big = fastestLoad(bigPath), written = fastestLoad(fanPath);
  EXPECT_LT(big, 10 * written + 0.01) << big << " s for the face, " << written << " s for its triangles written out";
  std::printf("300000-corner face: %.3f s, its triangles written out: %.3f s\n", big, written);
}

TEST(ObjReader, ContinuationsCommentsCrlfAndSkippedStatements) {
  const ObjData d = parseObj(
      "# a comment\r\n"
      "mtllib a.mtl b.mtl\r\n"
      "o thing\r\ng part one\r\ns 1\r\n"
      "v 1 \\\r\n  2 \\\n 3 # trailing comment\r\n"  // lines 6-8: one vertex
      "vt 0 0\nvn 0 0 1\nvp 0.5\n"
      "v 4 5 6\nv 7 8 9 1\n"
      "l 1 2\np 1\n"
      "usemtl red\r\n"
      "f 1 2 \\\n 3\n"
      "curv 0 1 1 2\nbogus\n"
      "usemtl green\nf 1 2 3\nusemtl red\nf 3 2 1\n"
      "\n   \t\n",
      "a.obj");
  ASSERT_EQ(d.vertices.size(), 3u);
  EXPECT_EQ(d.vertices[0].x, 1);
  EXPECT_EQ(d.vertices[0].y, 2);
  EXPECT_EQ(d.vertices[0].z, 3);
  EXPECT_EQ(d.vertices[2].z, 9);
  ASSERT_EQ(d.triangles.size(), 3u);
  ASSERT_EQ(d.materialNames, (std::vector<std::string>{"red", "green"}));
  EXPECT_EQ(d.triangleMaterial, (HugeVector<uint32_t>{0, 1, 0}));
  ASSERT_EQ(d.libraries.size(), 2u);
  EXPECT_EQ(d.libraries[1].name, "b.mtl");
  EXPECT_EQ(d.libraries[1].line, 2);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_EQ(d.warnings[0], "a.obj: skipped 2 statements with unknown keywords (first 'curv' at line 19)");
  // Line numbers after continuations and CRLF count physical lines; a continued statement is named by its first.
  EXPECT_EQ(objError("v 0 0 0\r\nv 1 \\\r\n 2 \\\r\n 3\r\nv x 0 0\r\n"), "a.obj:5: bad number 'x'");
  EXPECT_EQ(objError("v 0 0 0\nv 1 \\\n 2 \\\n x\n"), "a.obj:2: bad number 'x'");
  // A file whose last line ends in a backslash, and one without a final newline.
  EXPECT_EQ(parseObj("v 1 2 3 \\", "a.obj").vertices.size(), 1u);
  EXPECT_EQ(parseObj("v 1 2 3", "a.obj").vertices.size(), 1u);
}

TEST(ObjReader, SeventeenDigitsComeBackBitForBit) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> exponent(-300, 300), mantissa(1, 10), unit(0, 1);
  std::vector<double> values;
  for (int i = 0; i < 3000; ++i) {
    values.push_back((i % 2 ? -1 : 1) * mantissa(rng) * std::pow(10.0, exponent(rng)));
    values.push_back(1e7 + unit(rng));  // near a 1e7 offset, where float keeps no fraction at all
    values.push_back(std::bit_cast<double>(rng() & 0x7fefffffffffffffULL));  // any finite bit pattern
  }
  values.push_back(5e-324);
  values.push_back(-1.7976931348623157e308);
  while (values.size() % 3) values.push_back(0);
  std::string text;
  char buffer[64];
  for (size_t i = 0; i < values.size(); i += 3) {
    text += "v";
    for (int k = 0; k < 3; ++k) {
      std::snprintf(buffer, sizeof buffer, " %.17g", values[i + k]);
      text += buffer;
    }
    text += "\n";
  }
  const ObjData d = parseObj(text, "a.obj");
  ASSERT_EQ(d.vertices.size() * 3, values.size());
  for (size_t i = 0; i < values.size(); ++i)
    ASSERT_EQ(bits(d.vertices[i / 3][static_cast<int>(i % 3)]), bits(values[i])) << "value " << values[i];
}

TEST(ObjReader, AMeshOffsetBy1e7KeepsItsShapeExactly) {
  // In float, 1e7 + 0.1 and 1e7 + 0.2 are both 1e7 (float's spacing there is 1): the triangle collapsed.
  ScratchDir dir("objr");
  const std::string path = write(dir, "far.obj",
                                 "v 10000000.1 10000000.1 10000000.1\n"
                                 "v 10000000.2 10000000.1 10000000.1\n"
                                 "v 10000000.1 10000000.3 10000000.1\n"
                                 "f 1 2 3\n");
  const Scene s = loadScene(path);
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(bits(s.triangles[0].v[0].x), bits(10000000.1));
  EXPECT_EQ(bits(s.triangles[0].v[1].x), bits(10000000.2));
  EXPECT_EQ(bits(s.triangles[0].v[2].y), bits(10000000.3));
  EXPECT_FALSE(isDegenerate(s.triangles[0]));
}

TEST(ObjReader, MtlNumbersAreCheckedAndNamed) {
  std::vector<std::string> warnings;
  auto mtlError = [&](const std::string& text) { return inputError([&] { parseMtl(text, "m.mtl", warnings); }); };
  EXPECT_EQ(mtlError("newmtl a\nKd 1 1 1\nNs 1e999\n"), "m.mtl:3: bad number '1e999' in Ns");
  EXPECT_EQ(mtlError("newmtl a\nNs -1\n"), "m.mtl:2: Ns -1 is negative");
  EXPECT_EQ(mtlError("newmtl a\nNi -1.5\n"), "m.mtl:2: Ni -1.5 is negative");
  EXPECT_EQ(mtlError("newmtl a\nKd nan 0 0\n"), "m.mtl:2: bad number 'nan' in Kd");
  EXPECT_EQ(mtlError("newmtl a\nKs 1 1\n"), "m.mtl:2: Ks needs 1 or 3 numbers");
  EXPECT_EQ(mtlError("newmtl a\nKd 1 1 1 1\n"), "m.mtl:2: Kd needs 1 or 3 numbers");
  EXPECT_EQ(mtlError("newmtl a\nKd 0.5 -1 0\n"), "m.mtl:2: Kd value -1 is negative");
  EXPECT_EQ(mtlError("newmtl\n"), "m.mtl:1: newmtl needs a name");
  EXPECT_EQ(mtlError("Ns inf\nnewmtl a\n"), "m.mtl:1: bad number 'inf' in Ns");  // checked even before newmtl

  const auto m = parseMtl(
      "# comment\r\nnewmtl shiny metal\r\nKd 0.25\r\nKs 0.5 0.25 \\\n 0.125\nNs 96\nNi 1.5\nKa 1 1 1\nillum 2\n"
      "map_Kd tex.png\nnewmtl plain\nNi 0\n",
      "m.mtl", warnings);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].name, "shiny metal");
  EXPECT_EQ(m[0].diffuse.x, 0.25);
  EXPECT_EQ(m[0].diffuse.z, 0.25);
  EXPECT_EQ(m[0].specular.z, 0.125);
  EXPECT_EQ(m[0].exponent, 96);
  EXPECT_EQ(m[0].indexOfRefraction, 1.5);
  EXPECT_EQ(m[1].diffuse.x, 0);  // black without Kd, as tinyobjloader had it
  EXPECT_EQ(m[1].exponent, 1);
  EXPECT_EQ(m[1].indexOfRefraction, 1);  // Ni 0: "unset" in many exporters' files
  ASSERT_FALSE(warnings.empty());
  EXPECT_EQ(warnings.back(), "m.mtl:12: Ni 0 is no index of refraction; 1 is used");
}

TEST(ObjImport, Ns1e999IsRefusedNamingTheMtlFileAndLine) {
  ScratchDir dir("objr");
  write(dir, "m.mtl", "newmtl hot\nKd 1 0 0\nNs 1e999\n");
  const std::string path = write(dir, "a.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n");
  EXPECT_EQ(inputError([&] { loadScene(path); }), dir.file("m.mtl") + ":3: bad number '1e999' in Ns");
}

TEST(ObjImport, MaterialsMapByUsemtlWithTheDefaultLast) {
  ScratchDir dir("objr");
  write(dir, "a.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
  write(dir, "b.mtl", "newmtl blue\nKd 0 0 1\nNs 7\n");
  const std::string path = write(dir, "m.obj",
                                 "mtllib a.mtl\nmtllib b.mtl a.mtl\n"
                                 "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                 "f 1 2 3\n"
                                 "usemtl blue\nf 1 2 3\n"
                                 "usemtl red\nf 1 2 3\n"
                                 "usemtl nowhere\nf 1 2 3\n");
  const Scene s = loadScene(path);
  ASSERT_EQ(s.materials.size(), 4u);  // red, green, blue (a.mtl read once), default
  EXPECT_EQ(s.materials[3].name, "default");
  ASSERT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(s.triangles[0].material, 3u);
  EXPECT_EQ(s.materials[s.triangles[1].material].name, "blue");
  EXPECT_EQ(s.materials[s.triangles[1].material].exponent, 7);
  EXPECT_EQ(s.materials[s.triangles[2].material].name, "red");
  EXPECT_EQ(s.triangles[3].material, 3u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0], path + ":11: material 'nowhere' is not defined; default white is used");
}

TEST(ObjImport, MaterialLibrariesStayInTheObjFolder) {
  ScratchDir dir("objr");
  fs::create_directories(dir.path() / "scene" / "sub");
  write(dir, "outside.mtl", "newmtl x\nKd 1 0 0\n");
  write(dir, "scene/sub/in.mtl", "newmtl y\nKd 0 1 0\n");
  const std::string body = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  auto obj = [&](const std::string& mtllib) { return write(dir, "scene/a.obj", "mtllib " + mtllib + "\n" + body); };

  EXPECT_EQ(loadScene(obj("sub/in.mtl")).materials.size(), 2u);  // y and the default
  EXPECT_EQ(loadScene(obj("sub/../sub/in.mtl")).materials.size(), 2u);
  std::string path = obj("../outside.mtl");
  std::string message = inputError([&] { loadScene(path); });
  EXPECT_EQ(message.rfind(path + ":1: material library: '", 0), 0u) << message;
  EXPECT_NE(message.find("../outside.mtl': lies outside the folder of " + path), std::string::npos) << message;
  path = obj(dir.file("outside.mtl"));
  EXPECT_NE(inputError([&] {
              loadScene(path);
            }).find(":1: material library: '" + dir.file("outside.mtl") + "': absolute paths are refused"),
            std::string::npos);
  path = obj("sub/../../outside.mtl");
  EXPECT_NE(inputError([&] { loadScene(path); }).find("lies outside the folder"), std::string::npos);
  // A symbolic link inside the folder that leads out of it.
  fs::create_symlink(dir.file("outside.mtl"), dir.path() / "scene" / "link.mtl");
  path = obj("link.mtl");
  EXPECT_NE(inputError([&] { loadScene(path); }).find(":1: material library: '"), std::string::npos);
  EXPECT_NE(inputError([&] { loadScene(path); }).find("lies outside the folder"), std::string::npos);
  // Not a regular file: a directory, a FIFO (which would block a reader forever).
  path = obj("sub");
  EXPECT_EQ(inputError([&] { loadScene(path); }), path + ":1: material library 'sub' is not a regular file");
  ASSERT_EQ(::mkfifo((dir.path() / "scene" / "fifo.mtl").c_str(), 0600), 0);
  path = obj("fifo.mtl");
  EXPECT_EQ(inputError([&] { loadScene(path); }), path + ":1: material library 'fifo.mtl' is not a regular file");
  // A missing library is a warning: the faces get the default material.
  path = obj("missing.mtl");
  const Scene s = loadScene(path);
  ASSERT_EQ(s.materials.size(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            path + ":1: material library 'missing.mtl' not found; its materials are drawn in default white");
}

TEST(ObjImport, OversizedAndNonRegularFilesAreRefused) {
  ScratchDir dir("objr");
  fs::create_directories(dir.path() / "d.obj");
  EXPECT_EQ(inputError([&] { importObj(dir.file("d.obj")); }),
            dir.file("d.obj") + ": is a folder, expected the OBJ file");
  const std::string none = inputError([&] { importObj(dir.file("none.obj")); });
  EXPECT_EQ(none.rfind(dir.file("none.obj") + ": cannot open OBJ file", 0), 0u) << none;
  const std::string path = write(dir, "a.obj", "v 0 0 0\n");
  EXPECT_EQ(inputError([&] { readTextFile(path, "OBJ file", 4); }),
            path + ": OBJ file is 8 bytes, more than the limit of 4 bytes");
}

}  // namespace
}  // namespace vox
