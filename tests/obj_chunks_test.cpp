// Tests for reading an OBJ text in chunks on all threads (obj_chunks.cpp): for every text, in one piece and in
// chunks down to single lines, the same vertices (bit for bit), triangles, materials, texture coordinates,
// libraries, warnings, and the same first error.
#include "import/obj_chunks.h"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <random>
#include <string>
#include <vector>

#include "import/obj_reader.h"
#include "test_util.h"
#include "vox/core/error.h"

namespace vox {
namespace {

// The chunk sizes every text is read with: one piece, then cuts after every line, every few lines and at random.
const size_t kChunkings[] = {size_t{1} << 40, 1, 2, 3, 7, 16, 61, 250};

struct Reading {
  ObjData data;
  std::string error;  // the InputError's message, or "" when the text read
};

Reading readIn(const std::string& text, size_t chunkBytes) {
  Reading r;
  try {
    r.data = parseObj(text, "a.obj", chunkBytes);
  } catch (const InputError& e) {
    r.error = e.what();
  }
  return r;
}

// Every field of two readings, with the first difference named.
void expectSame(const Reading& a, const Reading& b, const std::string& what) {
  ASSERT_EQ(a.error, b.error) << what;
  const ObjData &x = a.data, &y = b.data;
  ASSERT_EQ(x.vertices.size(), y.vertices.size()) << what;
  for (size_t i = 0; i < x.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(std::bit_cast<uint64_t>(x.vertices[i][k]), std::bit_cast<uint64_t>(y.vertices[i][k])) << what;
  EXPECT_EQ(x.triangles, y.triangles) << what;
  EXPECT_EQ(x.triangleMaterial, y.triangleMaterial) << what;
  EXPECT_EQ(x.materialNames, y.materialNames) << what;
  EXPECT_EQ(x.materialLines, y.materialLines) << what;
  ASSERT_EQ(x.libraries.size(), y.libraries.size()) << what;
  for (size_t i = 0; i < x.libraries.size(); ++i) {
    EXPECT_EQ(x.libraries[i].name, y.libraries[i].name) << what;
    EXPECT_EQ(x.libraries[i].line, y.libraries[i].line) << what;
  }
  ASSERT_EQ(x.texcoords.size(), y.texcoords.size()) << what;
  for (size_t i = 0; i < x.texcoords.size(); ++i) {
    EXPECT_EQ(std::bit_cast<uint64_t>(x.texcoords[i].u), std::bit_cast<uint64_t>(y.texcoords[i].u)) << what;
    EXPECT_EQ(std::bit_cast<uint64_t>(x.texcoords[i].v), std::bit_cast<uint64_t>(y.texcoords[i].v)) << what;
  }
  EXPECT_EQ(x.triangleTexcoords, y.triangleTexcoords) << what;
  EXPECT_EQ(x.warnings, y.warnings) << what;
}

// Reads the text every way and expects one result; returns the one-piece reading.
Reading readEveryWay(const std::string& text) {
  const Reading whole = readIn(text, kChunkings[0]);
  for (size_t bytes : kChunkings) {
    expectSame(whole, readIn(text, bytes), "chunks of " + std::to_string(bytes) + " bytes of:\n" + text);
    if (::testing::Test::HasFatalFailure()) break;
  }
  return whole;
}

TEST(ObjChunks, ChunksEndWhereLogicalLinesEndAndCountWhatCameBefore) {
  const std::string text = "v 1 2 3\nvt 0 0\nv 4 \\\n 5 6\r\nf 1 2 \\\r\n 2\nvt 1 1\nv 7 8 9\n# v 0 0 0\n  v 1 1 1";
  const std::vector<ObjChunk> chunks = cutObjText(text, 1);
  std::string joined;
  for (const ObjChunk& c : chunks) joined += c.text;
  EXPECT_EQ(joined, text);
  // Lines 3-4 and 5-6 are continued, so they stay whole; every other line is a chunk of its own.
  ASSERT_EQ(chunks.size(), 8u);
  EXPECT_EQ(chunks[2].text, "v 4 \\\n 5 6\r\n");
  EXPECT_EQ(chunks[3].text, "f 1 2 \\\r\n 2\n");
  const long long lines[] = {0, 1, 2, 4, 6, 7, 8, 9};
  const size_t vertices[] = {0, 1, 1, 2, 2, 2, 3, 3};
  const size_t texcoords[] = {0, 0, 1, 1, 1, 2, 2, 2};
  const size_t trianglesBefore[] = {0, 0, 0, 0, 1, 1, 1, 1};
  const size_t ownVertices[] = {1, 0, 1, 0, 0, 1, 0, 1};
  const size_t ownTriangles[] = {0, 0, 0, 1, 0, 0, 0, 0};
  for (size_t k = 0; k < chunks.size(); ++k) {
    EXPECT_EQ(chunks[k].linesBefore, lines[k]) << k;
    EXPECT_EQ(chunks[k].verticesBefore, vertices[k]) << k;
    EXPECT_EQ(chunks[k].texcoordsBefore, texcoords[k]) << k;
    EXPECT_EQ(chunks[k].trianglesBefore, trianglesBefore[k]) << k;
    EXPECT_EQ(chunks[k].vertices, ownVertices[k]) << k;
    EXPECT_EQ(chunks[k].triangles, ownTriangles[k]) << k;
  }
  // A polygon of n corners counts n - 2 triangles, a comment ends its corners, and a face of fewer than 3 counts
  // none (the parser reports it).
  const std::vector<ObjChunk> faces = cutObjText("f 1 2 3 4 5 # 6 7\nf 1 2\nf 1 2 3\n", 1000);
  ASSERT_EQ(faces.size(), 1u);
  EXPECT_EQ(faces[0].triangles, 4u);
  // A text shorter than two chunks is one piece.
  EXPECT_EQ(cutObjText(text, text.size() / 2 + 1).size(), 1u);
  EXPECT_EQ(cutObjText("", 1).size(), 0u);
}

TEST(ObjChunks, IndicesMaterialsAndTexcoordsAcrossChunks) {
  const Reading r = readEveryWay(
      "mtllib a.mtl\n"
      "f 1 2 3\n"  // before any usemtl, and forward
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
      "usemtl red\n"
      "f -3 -2 -1\n"
      "v 0 0 1\nv 1 0 1\nv 0 1 1\nvt 0 1\n"
      "f -3/-1 -2/-2 -1/-3\n"  // the first textured face: earlier ones get none
      "usemtl green\n"
      "f 1/1 2/2 3/3 4/1\n"
      "mtllib b.mtl\nusemtl red\nfoo bar\n"
      "f 4 5 6\n"
      "usemtl blue\nbaz\n");
  ASSERT_EQ(r.error, "");
  EXPECT_EQ(r.data.triangles.size(), 6u);
  EXPECT_EQ(r.data.materialNames, (std::vector<std::string>{"red", "green", "blue"}));
  EXPECT_EQ(r.data.materialLines, (std::vector<long long>{8, 15, 21}));
  EXPECT_EQ(r.data.triangleMaterial, (HugeVector<uint32_t>{kNoObjMaterial, 0, 0, 1, 1, 0}));
  ASSERT_EQ(r.data.triangleTexcoords.size(), 6u);
  EXPECT_EQ(r.data.triangleTexcoords[1][0], kNoObjTexcoord);
  EXPECT_EQ(r.data.triangleTexcoords[2], (std::array<uint32_t, 3>{2, 1, 0}));
  EXPECT_EQ(r.data.triangleTexcoords[4], (std::array<uint32_t, 3>{0, 2, 0}));
  EXPECT_EQ(r.data.warnings,
            (std::vector<std::string>{"a.obj: skipped 2 statements with unknown keywords (first 'foo' at line 19)"}));
  ASSERT_EQ(r.data.libraries.size(), 2u);
  EXPECT_EQ(r.data.libraries[1].line, 17);
}

TEST(ObjChunks, TheFirstErrorOfTheFileIsReportedWhicheverChunkMeetsItFirst) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // An error in a later chunk that a thread may meet first, and one in an earlier chunk.
  EXPECT_EQ(readEveryWay(tri + "f -4 1 2\n" + tri + "v x 0 0\n").error,
            "a.obj:4: face index -4 out of range (3 vertices)");
  EXPECT_EQ(readEveryWay(tri + "f -6 1 2\n" + tri + "v x 0 0\n").error,
            "a.obj:4: face index -6 out of range (3 vertices)");
  EXPECT_EQ(readEveryWay(tri + tri + "f -6 1 2\n").error, "");
  // Forward indices are judged at the end: a later malformed line comes first, then vertex before texture indices.
  EXPECT_EQ(readEveryWay("f 1 2 9\n" + tri + "v x 0 0\n").error, "a.obj:5: bad number 'x'");
  EXPECT_EQ(readEveryWay("vt 0 0\nf 1/5 2/1 3/1\nf 1 2 9\n" + tri).error,
            "a.obj:3: face index 9 out of range (3 vertices)");
  EXPECT_EQ(readEveryWay("vt 0 0\nf 1/5 2/1 3/1\nf 1/-2 2 3\n" + tri).error,
            "a.obj:2: texture coordinate index 5 out of range (1 texture coordinates)");
  EXPECT_EQ(readEveryWay("vt 0 0\n" + tri + "f 1/-2 2/1 3/1\nvt 0 0\n").error,
            "a.obj:5: texture coordinate index -2 out of range (2 texture coordinates)");
  EXPECT_EQ(readEveryWay(tri + "f 1/7 2/8 3/9\n").error, "");  // no `vt` at all: texture indices ignored
  EXPECT_EQ(readEveryWay(tri + "f 1 2\n" + "f 0 1 2\n").error, "a.obj:4: face needs at least 3 vertices");
}

// A random OBJ text: vertices, texture coordinates, faces of 3-5 corners in every corner form with positive,
// negative and forward indices, materials, continuations, CRLF, comments, skipped and unknown statements; now and
// then a defect (a bad number, an index out of range, a short face).
std::string randomObj(std::mt19937& rng, bool defects) {
  std::uniform_int_distribution<int> pick(0, 99);
  std::string text;
  int vertices = 0, texcoords = 0;
  auto index = [&](int count) {  // mostly in range, now and then a forward index (in range at the end or not)
    const int i = pick(rng) < 95 ? pick(rng) % std::max(count, 1) : count + pick(rng) % 3;
    if (pick(rng) < 30 && i < count) return std::to_string(-(i + 1));
    return std::to_string(i + 1);
  };
  const int lines = 20 + pick(rng);
  for (int l = 0; l < lines; ++l) {
    const int kind = pick(rng);
    if (kind < 30) {
      text += "v " + std::to_string(pick(rng) * 0.37) + " -" + std::to_string(pick(rng)) + "e-3 " +
              std::to_string(pick(rng));
      ++vertices;
    } else if (kind < 40) {
      text += "vt 0." + std::to_string(pick(rng)) + " " + std::to_string(pick(rng) % 2);
      ++texcoords;
    } else if (kind < 75) {
      text += "f";
      const int corners = 3 + pick(rng) % 3;
      const int faceForm = pick(rng) % 4;
      for (int c = 0; c < corners; ++c) {
        text += " " + index(vertices);
        const int form = pick(rng) < 90 ? faceForm : pick(rng) % 4;
        if (form == 1) text += "/" + index(texcoords);
        if (form == 2) text += "//" + std::to_string(1 + pick(rng));
        if (form == 3) text += "/" + index(texcoords) + "/1";
      }
    } else if (kind < 82) {
      text += "usemtl m" + std::to_string(pick(rng) % 4);
    } else if (kind < 86) {
      text += "v 1 \\\n 2 \\\r\n 3";
      ++vertices;
    } else if (kind < 89) {
      text += "# v 1 2 3";
    } else if (kind < 92) {
      text += pick(rng) % 2 ? "g part" : "mtllib x" + std::to_string(pick(rng)) + ".mtl";
    } else if (kind < 95) {
      text += pick(rng) % 2 ? "curv 1 2" : "   ";
    } else if (defects && pick(rng) < 40) {
      const char* bad[] = {"v 1 nan 2", "f 1 2", "f 0 1 2", "v 1 2", "vt", "f 1 2 3/x"};
      text += bad[pick(rng) % 6];
    }
    text += pick(rng) < 20 ? "\r\n" : "\n";
  }
  return text;
}

TEST(ObjChunks, RandomTextsReadTheSameInEveryChunking) {
  std::mt19937 rng(26);
  int errors = 0, textured = 0;
  for (int t = 0; t < 400 && !HasFatalFailure(); ++t) {
    const Reading r = readEveryWay(randomObj(rng, t % 2 == 1));
    errors += !r.error.empty();
    textured += !r.data.triangleTexcoords.empty();
  }
  // The texts exercise both outcomes (a generator that only made errors or only valid files would test little).
  EXPECT_GT(errors, 100);
  EXPECT_LT(errors, 350);
  EXPECT_GT(textured, 20);
}

TEST(ObjChunks, TheSeedMeshesReadTheSameInOneAndInManyChunks) {
  for (const char* name : {"meshes/derived/sheencloth_115k.obj", "meshes/derived/stanford_bunny_69k.obj",
                           "meshes/teapot.obj", "meshes/spot.obj"}) {
    const std::string path = std::string(VOX_SEED_DIR) + "/" + name;
    const std::string text(readTextFile(path, "OBJ file", kMaxObjFileBytes).view());
    const Reading many = readIn(text, 4096);
    ASSERT_EQ(many.error, "");
    EXPECT_GT(cutObjText(text, 4096).size(), 10u);
    expectSame(readIn(text, size_t{1} << 40), many, name);
    expectSame(readIn(text, kObjChunkBytes), many, name);
  }
}

}  // namespace
}  // namespace vox
