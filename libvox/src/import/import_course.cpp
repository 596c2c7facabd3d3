// The MIT 6.837 (Fall 2004) text scene format; grammar in seed-scenes/6837/README.md ("Scene file grammar").
// Tokens are whitespace-separated words, keywords case-sensitive, no comments. Every error names file:line.
// TriangleMesh OBJ files are read by the OBJ reader shared with the OBJ importer (obj_reader.h: double precision,
// line-numbered errors); only their vertices and faces are used (the course's reader knows nothing else).
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "import/import_progress.h"
#include "import/obj_reader.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/input_file.h"

namespace vox {
namespace {

struct Token {
  std::string_view text;
  int line = 0;
};

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

std::vector<Token> tokenize(std::string_view text, ImportProgress& progress) {
  std::vector<Token> tokens;
  int line = 1;
  size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '\n') progress.step(uint64_t(++line), 0.1 + 0.2 * double(i) / double(text.size()));
    if (isSpace(text[i])) {
      ++i;
      continue;
    }
    const size_t start = i;
    while (i < text.size() && !isSpace(text[i])) ++i;
    tokens.push_back({text.substr(start, i - start), line});
  }
  return tokens;
}

// Parses a whole token as a finite double. std::from_chars would accept "nan" and "inf": refused here, since a
// scene coordinate must be a number. A leading '+' is accepted as scanf("%f") does.
std::optional<double> parseDouble(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<long long> parseInteger(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  long long value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// ---- scene parser ----

struct Primitives {
  HugeVector<Triangle> triangles;
  std::vector<Sphere> spheres;
  std::vector<Plane> planes;
};

// When the linear part L of `t` is a similarity (L^T L = s^2 I up to a relative 1e-12), returns s.
std::optional<double> similarityScale(const Mat4& t) {
  double g[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      g[i][j] = 0;
      for (int k = 0; k < 3; ++k) g[i][j] += t.m[k][i] * t.m[k][j];
    }
  const double s2 = (g[0][0] + g[1][1] + g[2][2]) / 3;
  if (!(s2 > 0) || !std::isfinite(s2)) return std::nullopt;
  constexpr double kTolerance = 1e-12;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::fabs(g[i][j] - (i == j ? s2 : 0.0)) > kTolerance * s2) return std::nullopt;
  return std::sqrt(s2);
}

class CourseParser {
 public:
  CourseParser(std::string path, const std::function<bool(double)>& progress)
      : path_(std::move(path)), progress_(progress, path_) {
    text_ = readInputFile(path_, "scene file");
    tokens_ = tokenize(text_, progress_);
    folder_ = std::filesystem::path(path_).parent_path();
  }

  Scene parse() {
    std::optional<Primitives> root;
    while (pos_ < tokens_.size()) {
      const Token t = next();
      if (t.text == "OrthographicCamera" || t.text == "PerspectiveCamera") {
        parseCamera(t.text == "OrthographicCamera");
      } else if (t.text == "Background") {
        parseBackground();
      } else if (t.text == "Lights") {
        parseLights();
      } else if (t.text == "Materials") {
        parseMaterials();
      } else if (t.text == "Group") {
        Primitives group;
        parseGroup(Mat4::identity(), group);
        root = std::move(group);  // the last top-level Group wins, as in the course's parser
      } else {
        failAt(t, "unknown keyword '", t.text, "'");
      }
    }
    if (root) {
      scene_.triangles = std::move(root->triangles);
      scene_.spheres = std::move(root->spheres);
      scene_.planes = std::move(root->planes);
    }
    if (scene_.materials.empty()) scene_.materials.push_back(Material{"default"});
    if (scene_.lights.empty()) {
      // The course's ray caster does the same: without lights it shows flat colours.
      scene_.ambient = {1, 1, 1};
      warn(path_, ": no lights; ambient light forced to 1 1 1 as the course's ray caster does");
    }
    return std::move(scene_);
  }

 private:
  template <typename... Parts>
  [[noreturn]] void failAt(const Token& t, const Parts&... parts) const {
    fail<InputError>(path_, ":", t.line, ": ", parts...);
  }

  template <typename... Parts>
  void warn(const Parts&... parts) {
    std::ostringstream out;
    (out << ... << parts);
    scene_.warnings.push_back(out.str());
  }

  int lastLine() const { return tokens_.empty() ? 1 : tokens_.back().line; }

  bool atEnd() const { return pos_ >= tokens_.size(); }

  Token next(const char* expected = nullptr) {
    if (atEnd()) {
      fail<InputError>(path_, ":", lastLine(), ": unexpected end of file",
                       expected ? std::string(" (expected ") + expected + ")" : std::string());
    }
    return tokens_[pos_++];
  }

  const Token* peek() const { return atEnd() ? nullptr : &tokens_[pos_]; }
  // The next token, for error positions; past the end, the last line.
  Token here() const { return atEnd() ? Token{"", lastLine()} : tokens_[pos_]; }

  void expect(std::string_view word) {
    const std::string w(word);
    const Token t = next(w.c_str());
    if (t.text != word) failAt(t, "expected '", word, "', found '", t.text, "'");
  }

  double readDouble() {
    const Token t = next("a number");
    const auto value = parseDouble(t.text);
    if (!value) failAt(t, "bad number '", t.text, "' (expected a finite number)");
    return *value;
  }

  long long readInteger() {
    const Token t = next("an integer");
    const auto value = parseInteger(t.text);
    if (!value) failAt(t, "bad integer '", t.text, "'");
    return *value;
  }

  long long readCount() {
    const Token t = next("a count");
    const auto value = parseInteger(t.text);
    if (!value) failAt(t, "bad count '", t.text, "'");
    if (*value < 0) failAt(t, "negative count ", *value);
    return *value;
  }

  Vec3 readVec3() {
    const double x = readDouble();
    const double y = readDouble();
    const double z = readDouble();
    return {x, y, z};
  }

  Vec3 readField(std::string_view name) {
    expect(name);
    return readVec3();
  }

  Vec3 readDirection(std::string_view name) {
    const Token at = here();
    const Vec3 d = readField(name);
    if (length(d) == 0) failAt(at, name, " is the zero vector");
    return d;
  }

  // ---- top-level blocks ----

  void parseCamera(bool orthographic) {
    expect("{");
    Camera cam;
    cam.kind = orthographic ? CameraKind::Orthographic : CameraKind::Perspective;
    // The course's generateRay takes a point of [0,1]^2 that spans the angle or size, and its glCanvas.C maps pixel
    // (i, j) of a W x H image to ((i + 0.5 - W/2) / max(W, H) + 0.5, likewise j): the square covers the longer side
    // and the shorter one sees the middle of it (its OrthographicCamera::glInit spreads `size` the same way).
    cam.span = CameraSpan::LongerSide;
    // The course's parser wants these fields in exactly this order.
    cam.center = readField("center");
    cam.direction = readDirection("direction");
    cam.up = readDirection("up");
    if (orthographic) {
      expect("size");
      const Token at = tokens_[pos_ - 1];
      cam.orthoHeight = readDouble();
      if (!(cam.orthoHeight > 0)) failAt(at, "camera size must be positive");
    } else {
      expect("angle");
      const Token at = tokens_[pos_ - 1];
      cam.fovDegrees = readDouble();
      if (!(cam.fovDegrees > 0 && cam.fovDegrees < 180)) failAt(at, "camera angle must be in (0, 180) degrees");
    }
    expect("}");
    scene_.camera = cam;
  }

  void parseBackground() {
    expect("{");
    for (;;) {
      const Token t = next("'}'");
      if (t.text == "}") break;
      if (t.text == "color")
        scene_.background = readVec3();
      else if (t.text == "ambientLight")
        scene_.ambient = readVec3();
      else
        failAt(t, "unknown Background field '", t.text, "'");
    }
  }

  void parseLights() {
    expect("{");
    expect("numLights");
    const long long n = readCount();
    for (long long i = 0; i < n; ++i) {
      const Token t = next("a light");
      Light light;
      if (t.text == "DirectionalLight") {
        expect("{");
        light.kind = LightKind::Directional;
        light.direction = normalize(readDirection("direction"));
        light.color = readField("color");
        expect("}");
      } else if (t.text == "PointLight") {
        expect("{");
        light.kind = LightKind::Point;
        light.position = readField("position");
        light.color = readField("color");
        const Token* p = peek();
        if (p && p->text == "attenuation") {
          ++pos_;
          light.attenuation = readVec3();
        }
        expect("}");
      } else {
        failAt(t, "unknown light '", t.text, "'");
      }
      scene_.lights.push_back(light);
    }
    expect("}");
  }

  void parseMaterials() {
    expect("{");
    expect("numMaterials");
    const long long n = readCount();
    // A Materials block replaces any earlier one, as the course's parser keeps only the last.
    std::vector<Material> materials;
    std::vector<SolidTexture> solidTextures;
    for (long long i = 0; i < n; ++i) {
      const Token t = next("a material");
      if (t.text == "Material" || t.text == "PhongMaterial") {
        materials.push_back(parsePhong());
      } else if (t.text == "Checkerboard" || t.text == "Noise" || t.text == "Marble" || t.text == "Wood") {
        const SolidTexture texture = parseSolidTexture(t, materials.size());
        // The plain fields are the first material's: what tools that draw one colour per material show.
        Material m = materials[texture.materials[0]];
        m.name = std::string(t.text);
        m.solidTexture = uint32_t(solidTextures.size());
        solidTextures.push_back(texture);
        materials.push_back(m);
      } else {
        failAt(t, "unknown material '", t.text, "'");
      }
    }
    expect("}");
    scene_.materials = std::move(materials);
    scene_.solidTextures = std::move(solidTextures);
  }

  Material parsePhong() {
    expect("{");
    Material m;
    for (;;) {
      const Token t = next("'}'");
      if (t.text == "}") break;
      if (t.text == "diffuseColor")
        m.diffuse = readVec3();
      else if (t.text == "specularColor")
        m.specular = readVec3();
      else if (t.text == "exponent")
        m.exponent = readDouble();
      else if (t.text == "reflectiveColor")
        m.reflective = readVec3();
      else if (t.text == "transparentColor")
        m.transparent = readVec3();
      else if (t.text == "indexOfRefraction")
        m.indexOfRefraction = readDouble();
      else
        failAt(t, "unknown material field '", t.text, "'");
    }
    return m;
  }

  // Reads a Checkerboard/Noise/Marble/Wood block. Its materialIndex fields must name materials defined before it,
  // so textures cannot form cycles; their nesting depth is checked by validateScene.
  SolidTexture parseSolidTexture(const Token& kind, size_t definedSoFar) {
    SolidTexture texture;
    texture.kind = kind.text == "Checkerboard" ? SolidKind::Checkerboard
                   : kind.text == "Noise"      ? SolidKind::Noise
                   : kind.text == "Marble"     ? SolidKind::Marble
                                               : SolidKind::Wood;
    expect("{");
    size_t indices = 0;
    for (;;) {
      const Token t = next("'}'");
      if (t.text == "}") break;
      if (t.text == "Transform") {
        expect("{");
        parseTransformOps(texture.transform);  // world points to texture space
        expect("}");
      } else if (t.text == "materialIndex") {
        const Token at = here();
        const long long k = readInteger();
        if (k < 0 || static_cast<size_t>(k) >= definedSoFar)
          failAt(at, "materialIndex ", k, " does not name a material defined before it (", definedSoFar, " so far)");
        if (indices == 2) failAt(t, kind.text, " has more than two materialIndex fields");
        texture.materials[indices++] = static_cast<uint32_t>(k);
      } else {
        parseSolidTextureNumber(kind, t, texture);
      }
    }
    if (indices != 2) failAt(kind, kind.text, " needs two materialIndex fields, found ", indices);
    return texture;
  }

  void parseSolidTextureNumber(const Token& kind, const Token& t, SolidTexture& texture) {
    if (t.text == "octaves" && kind.text != "Checkerboard") {
      const Token at = here();
      const long long n = readInteger();
      if (n < 0 || n > kMaxOctaves) failAt(at, "octaves ", n, " out of range (0..", kMaxOctaves, ")");
      texture.octaves = uint32_t(n);
    } else if (t.text == "frequency" && (kind.text == "Marble" || kind.text == "Wood")) {
      texture.frequency = readDouble();
    } else if (t.text == "amplitude" && (kind.text == "Marble" || kind.text == "Wood")) {
      texture.amplitude = readDouble();
    } else {
      failAt(t, "unknown ", kind.text, " field '", t.text, "'");
    }
  }

  // ---- transforms ----

  // Reads ops while the next word is one; M = M * Op for ops, M = Given * M for Matrix (the course's rule).
  void parseTransformOps(Mat4& m) {
    for (;;) {
      const Token* p = peek();
      if (!p) return;
      const Token t = *p;
      if (t.text == "Scale") {
        ++pos_;
        m = m * scaling(readVec3());
      } else if (t.text == "UniformScale") {
        ++pos_;
        const double s = readDouble();
        m = m * scaling({s, s, s});
      } else if (t.text == "Translate") {
        ++pos_;
        m = m * translation(readVec3());
      } else if (t.text == "XRotate" || t.text == "YRotate" || t.text == "ZRotate") {
        ++pos_;
        const Vec3 axis = t.text[0] == 'X' ? Vec3{1, 0, 0} : (t.text[0] == 'Y' ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
        m = m * rotation(axis, readDouble());
      } else if (t.text == "Rotate") {
        ++pos_;
        expect("{");
        const Vec3 axis = readVec3();
        const double degrees = readDouble();
        expect("}");
        if (length(axis) == 0) failAt(t, "Rotate axis is the zero vector");
        m = m * rotation(axis, degrees);
      } else if (t.text == "Matrix") {
        ++pos_;
        expect("{");
        Mat4 given;
        for (auto& row : given.m)
          for (double& x : row) x = readDouble();
        expect("}");
        m = given * m;
      } else {
        return;
      }
    }
  }

  // ---- objects ----

  uint32_t currentMaterial(const Token& at) {
    if (currentMaterial_) return *currentMaterial_;
    if (!scene_.materials.empty() && !warnedNoMaterial_) {
      warn(path_, ":", at.line, ": ", at.text, " before any MaterialIndex; using material 0");
      warnedNoMaterial_ = true;
    }
    return 0;
  }

  void parseObject(const Token& t, const Mat4& m, Primitives& out) {
    progress_.step(++objects_, 0.3 + 0.6 * double(pos_) / double(std::max<size_t>(tokens_.size(), 1)));
    // Objects nest through recursion; an absurd depth in an untrusted file must not overflow the stack.
    constexpr int kMaxNesting = 256;
    if (nesting_ >= kMaxNesting) failAt(t, "objects nested deeper than ", kMaxNesting);
    ++nesting_;
    parseObjectBody(t, m, out);
    --nesting_;
  }

  // Leaf objects are parsed out of line (noinline) so that the recursive frames stay small under sanitizers.
  [[gnu::noinline]] void parseTriangle(const Token& t, const Mat4& m, Primitives& out) {
    expect("{");
    Triangle tri;
    tri.v[0] = transformPoint(m, readField("vertex0"));
    tri.v[1] = transformPoint(m, readField("vertex1"));
    tri.v[2] = transformPoint(m, readField("vertex2"));
    expect("}");
    tri.material = currentMaterial(t);
    out.triangles.push_back(tri);
  }

  void parseObjectBody(const Token& t, const Mat4& m, Primitives& out) {
    if (t.text == "Group") {
      parseGroup(m, out);
    } else if (t.text == "Sphere") {
      parseSphere(t, m, out);
    } else if (t.text == "Plane") {
      parsePlane(t, m, out);
    } else if (t.text == "Triangle") {
      parseTriangle(t, m, out);
    } else if (t.text == "TriangleMesh") {
      parseTriangleMesh(t, m, out);
    } else if (t.text == "Transform") {
      expect("{");
      Mat4 local;
      parseTransformOps(local);
      const Token child = next("an object");
      parseObject(child, m * local, out);
      expect("}");
    } else {
      failAt(t, "unknown object '", t.text, "'");
    }
  }

  void parseGroup(const Mat4& m, Primitives& out) {
    expect("{");
    expect("numObjects");
    const long long n = readCount();
    long long count = 0;
    for (;;) {
      const Token t = next(count < n ? "an object" : "'}'");
      if (t.text == "MaterialIndex") {
        const long long k = readInteger();
        if (k < 0 || static_cast<size_t>(k) >= scene_.materials.size())
          failAt(t, "MaterialIndex ", k, " out of range (", scene_.materials.size(), " materials)");
        currentMaterial_ = static_cast<uint32_t>(k);
      } else if (count == n) {
        if (t.text != "}") failAt(t, "expected '}' after ", n, " objects, found '", t.text, "'");
        return;
      } else if (t.text == "}") {
        failAt(t, "Group ends after ", count, " of its ", n, " objects");
      } else {
        parseObject(t, m, out);
        ++count;
      }
    }
  }

  [[gnu::noinline]] void parseSphere(const Token& t, const Mat4& m, Primitives& out) {
    expect("{");
    Sphere s;
    s.center = readField("center");
    expect("radius");
    const Token at = tokens_[pos_ - 1];
    s.radius = readDouble();
    expect("}");
    if (!(s.radius > 0)) failAt(at, "sphere radius ", s.radius, " is not positive");
    s.material = currentMaterial(t);
    if (const auto scale = similarityScale(m)) {
      s.center = transformPoint(m, s.center);
      s.radius *= *scale;
    } else {
      if (linearDeterminant(m) == 0) failAt(t, "sphere under a singular transform");
      s.transform = m;  // an ellipsoid: the sphere stays in object space
    }
    out.spheres.push_back(s);
  }

  [[gnu::noinline]] void parsePlane(const Token& t, const Mat4& m, Primitives& out) {
    expect("{");
    const Vec3 n = readDirection("normal");
    expect("offset");
    const double d = readDouble();
    expect("}");
    Plane p;
    p.material = currentMaterial(t);
    const Vec3 onPlane = n * (d / dot(n, n));
    if (m.isIdentity()) {
      p.normal = normalize(n);
    } else {
      if (linearDeterminant(m) == 0) failAt(t, "plane under a singular transform");
      // Normals map by the inverse transpose of the linear part.
      p.normal = normalize(transformVector(transpose(inverse(m)), n));
    }
    p.offset = dot(p.normal, transformPoint(m, onPlane));
    out.planes.push_back(p);
  }

  [[gnu::noinline]] void parseTriangleMesh(const Token& t, const Mat4& m, Primitives& out) {
    expect("{");
    expect("obj_file");
    const Token name = next("a file name");
    expect("}");
    // Meshes are read only from the scene's own folder (and below), like glTF buffers and OBJ libraries.
    std::string objPath;
    try {
      objPath = resolveInsideFolder(path_, std::string(name.text));
    } catch (const InputError& e) {
      failAt(name, "mesh file: ", std::string(e.what()).substr(path_.size() + 2));
    }
    const std::string key = objPath;
    auto it = meshes_.find(key);
    if (it == meshes_.end()) {
      std::error_code ec;
      if (!std::filesystem::is_regular_file(objPath, ec)) failAt(name, "cannot open mesh file '", objPath, "'");
      it = meshes_.emplace(key, parseObj(readTextFile(objPath, "mesh file", kMaxObjFileBytes).view(), objPath)).first;
      for (const std::string& w : it->second.warnings) warn(w);
    }
    const ObjData& mesh = it->second;
    // Each instance copies the mesh: checked before the copy, so a scene instancing a large mesh thousands of
    // times is refused with its size instead of growing until memory runs out.
    const double triangles = double(out.triangles.size() + mesh.triangles.size());
    if (triangles * sizeof(Triangle) * 2 > double(memoryBudgetBytes()))
      checkMemory(triangles * sizeof(Triangle) * 2, path_ + ":" + std::to_string(t.line),
                  "TriangleMesh instancing " + std::to_string(uint64_t(triangles)) + " triangles");
    const uint32_t material = currentMaterial(t);
    std::vector<Vec3> world(mesh.vertices.size());
    for (size_t i = 0; i < world.size(); ++i) world[i] = transformPoint(m, mesh.vertices[i]);
    // No reserve(size() + n) here: growing by exactly n per mesh made thousands of instances quadratic;
    // push_back's geometric growth keeps the total linear.
    for (const auto& f : mesh.triangles) out.triangles.push_back({{world[f[0]], world[f[1]], world[f[2]]}, material});
  }

  std::string path_;
  // Asked every 4096th line and object: a scene of 600,000 triangles takes seconds to read.
  ImportProgress progress_;
  uint64_t objects_ = 0;
  std::string text_;
  std::vector<Token> tokens_;  // views into text_
  size_t pos_ = 0;
  std::filesystem::path folder_;
  Scene scene_;
  std::optional<uint32_t> currentMaterial_;
  bool warnedNoMaterial_ = false;
  std::map<std::string, ObjData> meshes_;
  int nesting_ = 0;
};

}  // namespace

Scene importCourseScene(const std::string& path, const std::function<bool(double)>& progress) {
  return CourseParser(path, progress).parse();
}

}  // namespace vox
