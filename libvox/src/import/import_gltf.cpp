// glTF 2.0 (.gltf, .glb) through tinygltf (Debian's 2.7.0, which includes <nlohmann/json.hpp> itself and
// stb_image.h by its plain name: /usr/include/stb is on the include path). This is the one translation unit that
// holds the tinygltf and stb implementations.
//
// Quirks relied on:
// - tinygltf 2.7 checks buffer sizes against byteLength but not accessor or bufferView ranges, nor node, mesh,
//   material or camera indices: everything used here is range-checked before it is read.
// - it does not enforce `extensionsRequired`, so KHR_materials_sheen or KHR_texture_transform listed as required
//   do not stop loading; we only want geometry from them.
// - node lights (KHR_lights_punctual) are not parsed into Node; we read node.extensions ourselves.
// - image decoding is replaced by keepImageBytes: stb_image never sees untrusted bytes; images named by uri (data or
//   file) keep their encoded bytes in Image::image, and those in bufferViews are read by GltfReader with range
//   checks (tinygltf hands the loader &buffer.data[byteOffset] without checking the view against the buffer).
//   Only images that a material's baseColorTexture uses are decoded, by OpenImageIO (texture_decode.h).
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "import/import_progress.h"
#include "vox/io/texture_decode.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/input_file.h"

namespace vox {
namespace {

bool keepImageBytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                    int size, void*) {
  if (image->bufferView != -1 || size <= 0) return true;  // bufferView images: see GltfReader::imageBytes
  image->image.assign(bytes, bytes + size);
  return true;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

size_t componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// Column-major glTF 4x4 (as in node.matrix) to our row-major Mat4.
Mat4 fromColumnMajor(const std::vector<double>& c) {
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k) out.m[r][k] = c[static_cast<size_t>(k * 4 + r)];
  return out;
}

// Unit quaternion (x, y, z, w) to a rotation matrix.
Mat4 fromQuaternion(double x, double y, double z, double w) {
  const double len = std::sqrt(x * x + y * y + z * z + w * w);
  if (len > 0) {
    x /= len;
    y /= len;
    z /= len;
    w /= len;
  }
  Mat4 r;
  r.m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0};
  r.m[1] = {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0};
  r.m[2] = {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0};
  return r;
}

// Without a scene every node that is nobody's child is a root.
std::vector<int> parentlessNodes(const tinygltf::Model& model) {
  std::vector<bool> isChild(model.nodes.size(), false);
  for (const auto& node : model.nodes)
    for (int c : node.children)
      if (c >= 0 && static_cast<size_t>(c) < isChild.size()) isChild[static_cast<size_t>(c)] = true;
  std::vector<int> roots;
  for (size_t i = 0; i < isChild.size(); ++i)
    if (!isChild[i]) roots.push_back(static_cast<int>(i));
  return roots;
}

class GltfReader {
 public:
  GltfReader(std::string path, const tinygltf::Model& model, ImportProgress& progress)
      : path_(std::move(path)), model_(model), progress_(progress) {}

  Scene read() {
    readMaterials();
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      int sceneIndex = model_.defaultScene;
      if (sceneIndex < 0 || static_cast<size_t>(sceneIndex) >= model_.scenes.size()) sceneIndex = 0;
      roots = model_.scenes[static_cast<size_t>(sceneIndex)].nodes;
    } else {
      roots = parentlessNodes(model_);
    }
    std::vector<bool> onPath(model_.nodes.size(), false);
    for (int root : roots) visitNode(root, Mat4::identity(), onPath, 0);

    if (usesDefaultMaterial_ || scene_.materials.empty() || !clones_.empty()) {
      // Index defaultMaterial_ == model_.materials.size(), reserved in readMaterials; clones follow it.
      scene_.materials.push_back(Material{"default"});
    }
    for (const Material& m : clones_) scene_.materials.push_back(m);
    if (!scene_.triangleUVs.empty()) scene_.triangleUVs.resize(scene_.triangles.size());
    return std::move(scene_);
  }

 private:
  template <typename... Parts>
  [[noreturn]] void failHere(const Parts&... parts) const {
    fail<InputError>(path_, ": ", parts...);
  }

  template <typename... Parts>
  void warn(const Parts&... parts) {
    std::ostringstream out;
    out << path_ << ": ";
    (out << ... << parts);
    scene_.warnings.push_back(out.str());
  }

  void readMaterials() {
    textureOf_.assign(model_.textures.size(), kUnread);
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const tinygltf::Material& m = model_.materials[i];
      Material out;
      out.name = m.name;
      const auto& f = m.pbrMetallicRoughness.baseColorFactor;
      if (f.size() >= 3) out.diffuse = {f[0], f[1], f[2]};
      const tinygltf::TextureInfo& info = m.pbrMetallicRoughness.baseColorTexture;
      if (info.index >= 0) {
        out.diffuseTexture = readTexture(int(i), info.index);
        if (info.extensions.count("KHR_texture_transform"))
          warn("material ", i, ": KHR_texture_transform of the base colour texture is ignored");
      }
      texCoordSet_.push_back(info.texCoord);
      scene_.materials.push_back(out);
    }
    defaultMaterial_ = static_cast<uint32_t>(scene_.materials.size());
  }

  static TextureWrap wrapMode(int glMode) {
    switch (glMode) {
      case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
        return TextureWrap::ClampToEdge;
      case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
        return TextureWrap::MirroredRepeat;
      case TINYGLTF_TEXTURE_WRAP_REPEAT:
        return TextureWrap::Repeat;
      default:
        return TextureWrap(255);
    }
  }

  // The scene texture of glTF texture `index` (decoded once, however many materials use it), or kNoTexture with
  // a warning when its image is in a format outside core glTF (no `source`).
  uint32_t readTexture(int material, int index) {
    if (size_t(index) >= model_.textures.size())
      failHere("material ", material, ": baseColorTexture ", index, " does not exist (", model_.textures.size(),
               " textures)");
    uint32_t& slot = textureOf_[size_t(index)];
    if (slot != kUnread) return slot;
    const tinygltf::Texture& t = model_.textures[size_t(index)];
    slot = kNoTexture;
    if (t.source < 0) {
      warn("texture ", index, ": no PNG or JPEG source (an extension's image?); material ", material,
           " uses its baseColorFactor");
      return slot;
    }
    if (size_t(t.source) >= model_.images.size())
      failHere("texture ", index, ": image ", t.source, " does not exist (", model_.images.size(), " images)");
    const tinygltf::Image& image = model_.images[size_t(t.source)];
    const std::string where = path_ + ": image " + std::to_string(t.source);
    const bool dataUri = image.uri.rfind("data:", 0) == 0;
    std::string name = "image " + std::to_string(t.source);
    if (!dataUri && !image.uri.empty()) name = image.uri;
    if (image.uri.empty() && !image.name.empty()) name = image.name;
    Texture texture = decodeTexture(imageBytes(t.source), dataUri ? "" : name, where);
    texture.name = name;
    if (t.sampler >= 0) {
      if (size_t(t.sampler) >= model_.samplers.size())
        failHere("texture ", index, ": sampler ", t.sampler, " does not exist (", model_.samplers.size(), " samplers)");
      const tinygltf::Sampler& s = model_.samplers[size_t(t.sampler)];
      texture.wrapU = wrapMode(s.wrapS);
      texture.wrapV = wrapMode(s.wrapT);
      if (texture.wrapU == TextureWrap(255) || texture.wrapV == TextureWrap(255))
        failHere("sampler ", t.sampler, ": wrap mode ", s.wrapS, " / ", s.wrapT, " is not a glTF wrap mode");
    }
    slot = uint32_t(scene_.textures.size());
    scene_.textures.push_back(std::move(texture));
    return slot;
  }

  // The encoded bytes of image `index`: kept by keepImageBytes for uris, read from the bufferView here.
  std::string imageBytes(int index) {
    const tinygltf::Image& image = model_.images[size_t(index)];
    if (image.bufferView == -1) {
      if (image.image.empty()) failHere("image ", index, ": no image data (uri '", quoteInput(image.uri), "')");
      return std::string(image.image.begin(), image.image.end());
    }
    if (image.bufferView < 0 || size_t(image.bufferView) >= model_.bufferViews.size())
      failHere("image ", index, ": bufferView ", image.bufferView, " does not exist");
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(image.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
      failHere("image ", index, ": bufferView ", image.bufferView, ": buffer ", bv.buffer, " does not exist");
    const std::vector<unsigned char>& data = model_.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
      failHere("image ", index, ": bufferView ", image.bufferView, " (offset ", bv.byteOffset, ", length ",
               bv.byteLength, ") exceeds buffer ", bv.buffer, " (", data.size(), " bytes)");
    const auto* begin = reinterpret_cast<const char*>(data.data()) + bv.byteOffset;
    return std::string(begin, bv.byteLength);
  }

  // A copy of textured `material` without its texture, for primitives that have no texture coordinates.
  uint32_t untexturedClone(uint32_t material) {
    for (size_t k = 0; k < clones_.size(); ++k)
      if (cloneOf_[k] == material) return defaultMaterial_ + 1 + uint32_t(k);
    Material m = scene_.materials[material];
    m.diffuseTexture = kNoTexture;
    clones_.push_back(m);
    cloneOf_.push_back(material);
    return defaultMaterial_ + uint32_t(clones_.size());
  }

  // TEXCOORD_n of a primitive as doubles (float exactly; normalized unsigned bytes and shorts as the glTF
  // specification maps them), one per vertex.
  std::vector<TexCoord> readTexCoords(int accessorIndex, size_t vertexCount) {
    if (accessorIndex < 0 || static_cast<size_t>(accessorIndex) >= model_.accessors.size())
      failHere("accessor ", accessorIndex, " does not exist (", model_.accessors.size(), " accessors)");
    const tinygltf::Accessor& a = model_.accessors[static_cast<size_t>(accessorIndex)];
    const int ct = a.componentType;
    const bool isFloat = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
    if (a.type != TINYGLTF_TYPE_VEC2 || !(isFloat || (a.normalized && (ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                                       ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))))
      failHere("accessor ", accessorIndex, ": TEXCOORD must be VEC2 of float or normalized unsigned byte or short");
    const size_t size = componentSize(ct);
    const View view = accessorView(accessorIndex, 2 * size);
    if (view.count != vertexCount)
      failHere("accessor ", accessorIndex, ": ", view.count, " texture coordinates for ", vertexCount, " vertices");
    std::vector<TexCoord> out(view.count);
    for (size_t i = 0; i < view.count; ++i) {
      const unsigned char* p = view.base + i * view.stride;
      double uv[2];
      for (int k = 0; k < 2; ++k) {
        if (isFloat) {
          float f;
          std::memcpy(&f, p + 4 * k, 4);
          uv[k] = f;
        } else if (size == 1) {
          uv[k] = p[k] / 255.0;
        } else {
          uint16_t v16;
          std::memcpy(&v16, p + 2 * k, 2);
          uv[k] = v16 / 65535.0;
        }
        if (!std::isfinite(uv[k])) failHere("accessor ", accessorIndex, ": texture coordinate ", i, " is not finite");
      }
      out[i] = {uv[0], uv[1]};
    }
    return out;
  }

  // The recursion keeps only a matrix per level; everything with a large frame (error formatting, mesh reading)
  // lives in enterNode, kept out of line so that 256 levels stay far inside the stack even under sanitizers.
  void visitNode(int index, const Mat4& parent, std::vector<bool>& onPath, int depth) {
    const Mat4 world = enterNode(index, parent, onPath, depth);
    const size_t i = static_cast<size_t>(index);
    onPath[i] = true;
    for (int child : model_.nodes[i].children) visitNode(child, world, onPath, depth + 1);
    onPath[i] = false;
  }

  // Checks node `index`, reads its camera, light and mesh, and returns its world matrix.
  [[gnu::noinline]] Mat4 enterNode(int index, const Mat4& parent, const std::vector<bool>& onPath, int depth) {
    if (index < 0 || static_cast<size_t>(index) >= model_.nodes.size())
      failHere("node ", index, " does not exist (", model_.nodes.size(), " nodes)");
    const size_t i = static_cast<size_t>(index);
    if (onPath[i]) failHere("node ", index, ": cycle in the node hierarchy");
    constexpr int kMaxDepth = 256;  // recursion depth
    if (depth > kMaxDepth) failHere("node ", index, ": hierarchy deeper than ", kMaxDepth);
    // glTF requires strict trees, but a file that shares subtrees could make the walk exponential: cap it.
    constexpr size_t kMaxVisits = 1'000'000;
    if (++visits_ > kMaxVisits) failHere("node ", index, ": more than ", kMaxVisits, " node visits (shared subtrees?)");
    const tinygltf::Node& node = model_.nodes[i];

    Mat4 local;
    if (node.matrix.size() == 16) {
      local = fromColumnMajor(node.matrix);
    } else {
      if (!node.matrix.empty()) failHere("node ", index, ": matrix has ", node.matrix.size(), " numbers, not 16");
      Mat4 t, r, s;
      if (node.translation.size() == 3)
        t = translation({node.translation[0], node.translation[1], node.translation[2]});
      else if (!node.translation.empty())
        failHere("node ", index, ": translation needs 3 numbers");
      if (node.rotation.size() == 4)
        r = fromQuaternion(node.rotation[0], node.rotation[1], node.rotation[2], node.rotation[3]);
      else if (!node.rotation.empty())
        failHere("node ", index, ": rotation needs 4 numbers");
      if (node.scale.size() == 3)
        s = scaling({node.scale[0], node.scale[1], node.scale[2]});
      else if (!node.scale.empty())
        failHere("node ", index, ": scale needs 3 numbers");
      local = t * r * s;  // glTF: T * R * S
    }
    const Mat4 world = parent * local;

    if (node.camera >= 0 && !scene_.camera) readCamera(index, node.camera, world);
    readLight(index, node, world);
    if (node.mesh >= 0) readMesh(index, node.mesh, world);
    return world;
  }

  void readCamera(int nodeIndex, int cameraIndex, const Mat4& world) {
    if (static_cast<size_t>(cameraIndex) >= model_.cameras.size())
      failHere("node ", nodeIndex, ": camera ", cameraIndex, " does not exist");
    const tinygltf::Camera& c = model_.cameras[static_cast<size_t>(cameraIndex)];
    Camera cam;
    if (c.type == "perspective") {
      cam.kind = CameraKind::Perspective;
      cam.fovDegrees = c.perspective.yfov * 180.0 / M_PI;
      if (!(cam.fovDegrees > 0 && cam.fovDegrees < 180))
        failHere("camera ", cameraIndex, ": yfov ", c.perspective.yfov, " is not in (0, pi)");
    } else if (c.type == "orthographic") {
      cam.kind = CameraKind::Orthographic;
      cam.orthoHeight = 2 * std::fabs(c.orthographic.ymag);
      if (!(cam.orthoHeight > 0)) failHere("camera ", cameraIndex, ": ymag must not be zero");
    } else {
      failHere("camera ", cameraIndex, ": unknown type '", c.type, "'");
    }
    // glTF cameras look down their local -Z with +Y up.
    cam.center = transformPoint(world, {0, 0, 0});
    cam.direction = normalize(transformVector(world, {0, 0, -1}));
    cam.up = normalize(transformVector(world, {0, 1, 0}));
    if (length(cam.direction) == 0 || length(cam.up) == 0)
      failHere("node ", nodeIndex, ": camera under a singular transform");
    scene_.camera = cam;
  }

  void readLight(int nodeIndex, const tinygltf::Node& node, const Mat4& world) {
    const auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext == node.extensions.end() || !ext->second.IsObject() || !ext->second.Has("light")) return;
    const tinygltf::Value& v = ext->second.Get("light");
    if (!v.IsNumber()) failHere("node ", nodeIndex, ": KHR_lights_punctual light is not a number");
    const int lightIndex = v.GetNumberAsInt();
    if (lightIndex < 0 || static_cast<size_t>(lightIndex) >= model_.lights.size())
      failHere("node ", nodeIndex, ": light ", lightIndex, " does not exist (", model_.lights.size(), " lights)");
    const tinygltf::Light& l = model_.lights[static_cast<size_t>(lightIndex)];
    Light out;
    Vec3 color{1, 1, 1};
    if (l.color.size() >= 3) color = {l.color[0], l.color[1], l.color[2]};
    // Physical intensities (lux, candela) mean nothing to a Phong shader without exposure: see import.h.
    out.color = color * std::min(l.intensity, 1.0);
    if (l.type == "directional") {
      out.kind = LightKind::Directional;
      out.direction = normalize(transformVector(world, {0, 0, -1}));
    } else if (l.type == "point" || l.type == "spot") {
      out.kind = LightKind::Point;
      out.position = transformPoint(world, {0, 0, 0});
      out.attenuation = {1, 0, 0};
      if (l.type == "spot") warn("light ", lightIndex, " (node ", nodeIndex, "): spot light imported as a point light");
    } else {
      warn("light ", lightIndex, ": unknown type '", l.type, "' skipped");
      return;
    }
    scene_.lights.push_back(out);
  }

  // A validated view of an accessor's elements: element i starts at base + i * stride.
  struct View {
    const unsigned char* base = nullptr;
    size_t stride = 0;
    size_t count = 0;
  };

  View accessorView(int accessorIndex, size_t elementSize) {
    if (accessorIndex < 0 || static_cast<size_t>(accessorIndex) >= model_.accessors.size())
      failHere("accessor ", accessorIndex, " does not exist (", model_.accessors.size(), " accessors)");
    const tinygltf::Accessor& a = model_.accessors[static_cast<size_t>(accessorIndex)];
    if (a.sparse.isSparse) failHere("accessor ", accessorIndex, ": sparse accessors are not supported");
    if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= model_.bufferViews.size())
      failHere("accessor ", accessorIndex, ": bufferView ", a.bufferView, " does not exist");
    const tinygltf::BufferView& bv = model_.bufferViews[static_cast<size_t>(a.bufferView)];
    if (bv.buffer < 0 || static_cast<size_t>(bv.buffer) >= model_.buffers.size())
      failHere("accessor ", accessorIndex, ": bufferView ", a.bufferView, ": buffer ", bv.buffer, " does not exist");
    const std::vector<unsigned char>& data = model_.buffers[static_cast<size_t>(bv.buffer)].data;
    // All in unsigned 64-bit with explicit overflow guards: the numbers come from an untrusted file.
    const uint64_t size = data.size();
    if (bv.byteOffset > size || bv.byteLength > size - bv.byteOffset)
      failHere("accessor ", accessorIndex, ": bufferView ", a.bufferView, " (offset ", bv.byteOffset, ", length ",
               bv.byteLength, ") exceeds buffer ", bv.buffer, " (", size, " bytes)");
    const size_t stride = bv.byteStride ? bv.byteStride : elementSize;
    if (stride < elementSize)
      failHere("accessor ", accessorIndex, ": byteStride ", stride, " is smaller than an element (", elementSize,
               " bytes)");
    View view{nullptr, stride, a.count};
    if (a.count == 0) return view;
    const uint64_t limit = std::numeric_limits<uint64_t>::max() / 2;
    if (a.count > limit / stride) failHere("accessor ", accessorIndex, ": count ", a.count, " is too large");
    const uint64_t span = uint64_t(a.count - 1) * stride + elementSize;
    if (a.byteOffset > bv.byteLength || span > bv.byteLength - a.byteOffset)
      failHere("accessor ", accessorIndex, ": offset ", a.byteOffset, " + ", a.count, " elements of stride ", stride,
               " exceeds bufferView ", a.bufferView, " (", bv.byteLength, " bytes)");
    view.base = data.data() + bv.byteOffset + a.byteOffset;
    return view;
  }

  std::vector<Vec3> readPositions(int accessorIndex) {
    if (accessorIndex < 0 || static_cast<size_t>(accessorIndex) >= model_.accessors.size())
      failHere("accessor ", accessorIndex, " does not exist (", model_.accessors.size(), " accessors)");
    const tinygltf::Accessor& a = model_.accessors[static_cast<size_t>(accessorIndex)];
    if (a.type != TINYGLTF_TYPE_VEC3 || a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
      failHere("accessor ", accessorIndex, ": POSITION must be float VEC3 (quantized positions are not supported)");
    const View view = accessorView(accessorIndex, 12);
    std::vector<Vec3> out(view.count);
    for (size_t i = 0; i < view.count; ++i) {
      progress_.step(i, 0.5);
      float xyz[3];
      std::memcpy(xyz, view.base + i * view.stride, sizeof xyz);
      out[i] = {xyz[0], xyz[1], xyz[2]};
    }
    return out;
  }

  std::vector<uint32_t> readIndices(int accessorIndex, size_t vertexCount) {
    const tinygltf::Accessor& a = model_.accessors.at(static_cast<size_t>(accessorIndex));
    if (a.type != TINYGLTF_TYPE_SCALAR) failHere("accessor ", accessorIndex, ": indices must be SCALAR");
    const int ct = a.componentType;
    if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      failHere("accessor ", accessorIndex, ": indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    const size_t size = componentSize(ct);
    const View view = accessorView(accessorIndex, size);
    std::vector<uint32_t> out(view.count);
    for (size_t i = 0; i < view.count; ++i) {
      progress_.step(i, 0.5);
      const unsigned char* p = view.base + i * view.stride;
      uint32_t value = 0;
      if (size == 1) {
        value = p[0];
      } else if (size == 2) {
        uint16_t v16;
        std::memcpy(&v16, p, 2);
        value = v16;
      } else {
        std::memcpy(&value, p, 4);
      }
      if (value >= vertexCount)
        failHere("accessor ", accessorIndex, ": index ", value, " at element ", i, " out of range (", vertexCount,
                 " vertices)");
      out[i] = value;
    }
    return out;
  }

  void readMesh(int nodeIndex, int meshIndex, const Mat4& world) {
    if (static_cast<size_t>(meshIndex) >= model_.meshes.size())
      failHere("node ", nodeIndex, ": mesh ", meshIndex, " does not exist (", model_.meshes.size(), " meshes)");
    const tinygltf::Mesh& mesh = model_.meshes[static_cast<size_t>(meshIndex)];
    bool warnedMode = false;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        if (!warnedMode)
          warn("mesh ", meshIndex, " '", mesh.name, "': primitives of mode ", mode,
               " (points or lines) skipped: they are not surfaces");
        warnedMode = true;
        continue;
      }
      const auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end()) {
        warn("mesh ", meshIndex, " '", mesh.name, "' primitive ", p, ": no POSITION, skipped");
        continue;
      }
      std::vector<Vec3> vertices = readPositions(pos->second);
      for (Vec3& v : vertices) v = transformPoint(world, v);
      std::vector<uint32_t> index;
      if (prim.indices >= 0) {
        if (static_cast<size_t>(prim.indices) >= model_.accessors.size())
          failHere("mesh ", meshIndex, " primitive ", p, ": indices accessor ", prim.indices, " does not exist");
        index = readIndices(prim.indices, vertices.size());
      } else {
        index.resize(vertices.size());
        for (size_t i = 0; i < index.size(); ++i) index[i] = static_cast<uint32_t>(i);
      }
      uint32_t material = defaultMaterial_;
      if (prim.material >= 0 && static_cast<size_t>(prim.material) < model_.materials.size())
        material = static_cast<uint32_t>(prim.material);
      else if (prim.material >= 0)
        failHere("mesh ", meshIndex, " primitive ", p, ": material ", prim.material, " does not exist");
      else
        usesDefaultMaterial_ = true;
      std::vector<TexCoord> uv;
      if (material < model_.materials.size() && scene_.materials[material].diffuseTexture != kNoTexture) {
        const int set = texCoordSet_[material];
        const auto tc = prim.attributes.find("TEXCOORD_" + std::to_string(set));
        if (tc != prim.attributes.end()) {
          uv = readTexCoords(tc->second, vertices.size());
        } else {
          warn("mesh ", meshIndex, " primitive ", p, ": no TEXCOORD_", set, " for the base colour texture of material ",
               material, "; its baseColorFactor is used");
          material = untexturedClone(material);
        }
      }

      auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        progress_.step(scene_.triangles.size(), 0.6);
        scene_.triangles.push_back({{vertices[a], vertices[b], vertices[c]}, material});
        if (!uv.empty()) {
          scene_.triangleUVs.resize(scene_.triangles.size() - 1);  // zeros for the untextured triangles before
          scene_.triangleUVs.push_back({uv[a], uv[b], uv[c]});
        } else if (!scene_.triangleUVs.empty()) {
          scene_.triangleUVs.push_back({});
        }
      };
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (index.size() % 3 != 0)
          warn("mesh ", meshIndex, " primitive ", p, ": ", index.size(), " indices is not a multiple of 3; ",
               index.size() % 3, " ignored");
        for (size_t i = 0; i + 2 < index.size(); i += 3) emit(index[i], index[i + 1], index[i + 2]);
      } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // Every other triangle is flipped to keep the strip's winding (glTF spec 3.7.2.1).
        for (size_t i = 0; i + 2 < index.size(); ++i)
          if (i % 2 == 0)
            emit(index[i], index[i + 1], index[i + 2]);
          else
            emit(index[i + 1], index[i], index[i + 2]);
      } else {
        for (size_t i = 1; i + 1 < index.size(); ++i) emit(index[0], index[i], index[i + 1]);
      }
    }
  }

  std::string path_;
  const tinygltf::Model& model_;
  ImportProgress& progress_;  // asked every 4096th vertex, index and triangle: 6 million triangles take seconds
  Scene scene_;
  uint32_t defaultMaterial_ = 0;
  bool usesDefaultMaterial_ = false;
  static constexpr uint32_t kUnread = kNoTexture - 1;
  std::vector<uint32_t> textureOf_;  // glTF texture -> scene texture, kNoTexture, or kUnread
  std::vector<int> texCoordSet_;     // per glTF material: the TEXCOORD_n of its base colour texture
  std::vector<Material> clones_;     // untextured copies, materials defaultMaterial_ + 1 + k
  std::vector<uint32_t> cloneOf_;
  size_t visits_ = 0;
};

// Nesting deeper than this is refused before the JSON reaches tinygltf, whose recursive parser (nlohmann::json)
// overflows the stack at some ten thousand levels. Real glTF nests a handful of levels; extras a few more.
constexpr int kMaxJsonDepth = 256;

// The deepest nesting of [ and { in `json`, ignoring brackets inside strings (with their escapes).
int jsonDepth(std::string_view json) {
  int depth = 0, deepest = 0;
  bool inString = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (inString) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > kMaxJsonDepth) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// The JSON text of a .gltf, or the JSON chunk of a .glb (whose header tinygltf checks again).
std::string_view jsonPart(const std::string& bytes, bool binary) {
  if (!binary) return bytes;
  uint32_t chunkLength = 0;
  if (bytes.size() < 20) return {};
  std::memcpy(&chunkLength, bytes.data() + 12, 4);
  return std::string_view(bytes).substr(20, chunkLength);
}

// tinygltf's file callbacks, narrowed: every external file (buffer or image uri) must resolve inside the glTF's
// own folder and be a regular file. tinygltf also looks in the current folder, and its default path expansion
// runs wordexp; neither happens here. The first refusal is kept for the error message.
struct FolderGuard {
  std::string gltfPath;
  std::string refusal;
};

bool guardedFileExists(const std::string& path, void* user) {
  auto& guard = *static_cast<FolderGuard*>(user);
  try {
    requireRegularFile(requireInsideFolder(guard.gltfPath, path), "glTF buffer or image");
    return true;
  } catch (const Error& e) {
    if (guard.refusal.empty()) guard.refusal = e.what();
    return false;
  }
}

std::string keepPath(const std::string& path, void*) { return path; }

bool guardedReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  if (!guardedFileExists(path, user)) {
    if (err) *err = static_cast<FolderGuard*>(user)->refusal;
    return false;
  }
  try {
    const std::string bytes = readInputFile(path, "glTF buffer or image");
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const Error& e) {
    auto& guard = *static_cast<FolderGuard*>(user);
    if (guard.refusal.empty()) guard.refusal = e.what();
    if (err) *err = e.what();
    return false;
  }
}

bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed while importing";
  return false;
}

// Triangles a primitive declares, from its accessor counts alone (the reader checks the accessors later).
double declaredTriangles(const tinygltf::Model& model, const tinygltf::Primitive& prim) {
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  int accessor = prim.indices;
  if (accessor < 0) {
    const auto pos = prim.attributes.find("POSITION");
    accessor = pos == prim.attributes.end() ? -1 : pos->second;
  }
  if (accessor < 0 || size_t(accessor) >= model.accessors.size()) return 0;
  const double n = double(model.accessors[size_t(accessor)].count);
  if (mode == TINYGLTF_MODE_TRIANGLES) return std::floor(n / 3);
  if (mode == TINYGLTF_MODE_TRIANGLE_STRIP || mode == TINYGLTF_MODE_TRIANGLE_FAN) return std::max(0.0, n - 2);
  return 0;
}

// Nodes instance meshes, and a small file can ask for billions of triangles (100 nodes x 100 primitives of a
// shared accessor). Their total over the node hierarchy is counted first, memoised per node so shared subtrees
// cost nothing, and refused before any triangle is made when it cannot fit.
class InstanceCounter {
 public:
  explicit InstanceCounter(const tinygltf::Model& model) : model_(model), memo_(model.nodes.size(), -1) {}

  double node(int index, int depth) {
    // Out-of-range, cyclic and too deep hierarchies are the reader's to report; they add nothing here.
    if (index < 0 || size_t(index) >= model_.nodes.size() || depth > 256) return 0;
    double& memo = memo_[size_t(index)];
    if (memo >= 0) return memo;
    memo = 0;  // a cycle back to this node adds nothing
    const tinygltf::Node& n = model_.nodes[size_t(index)];
    double total = 0;
    if (n.mesh >= 0 && size_t(n.mesh) < model_.meshes.size())
      for (const auto& prim : model_.meshes[size_t(n.mesh)].primitives) total += declaredTriangles(model_, prim);
    for (int child : n.children) total += node(child, depth + 1);
    memo = total;
    return total;
  }

 private:
  const tinygltf::Model& model_;
  std::vector<double> memo_;
};

void checkInstancedTriangles(const std::string& path, const tinygltf::Model& model, bool textured) {
  InstanceCounter count(model);
  double total = 0;
  if (!model.scenes.empty()) {
    int sceneIndex = model.defaultScene;
    if (sceneIndex < 0 || size_t(sceneIndex) >= model.scenes.size()) sceneIndex = 0;
    for (int root : model.scenes[size_t(sceneIndex)].nodes) total += count.node(root, 0);
  } else {
    for (int root : parentlessNodes(model)) total += count.node(root, 0);
  }
  // A triangle costs its world-space copy (sizeof(Triangle)), its texture coordinates in a textured scene, and, in
  // the grid, at least one reference.
  const double uvBytes = textured ? double(sizeof(std::array<TexCoord, 3>)) : 0;
  checkMemory(total * (double(sizeof(Triangle) + 8) + uvBytes), path,
              "instancing " + std::to_string(uint64_t(std::min(total, 1e19))) + " triangles");
}

// The uris of buffers and images, checked before tinygltf reads any: each must name a regular file inside the
// glTF's folder. (The file callbacks above check again what tinygltf actually opens.) Percent-escapes are decoded
// first, as tinygltf does, so "%2E%2E/" is "../".
std::string percentDecoded(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

void checkExternalUris(const std::string& path, std::string_view json) {
  const nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end(), nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return;  // tinygltf reports malformed JSON
  for (const char* kind : {"buffers", "images"}) {
    const auto list = doc.find(kind);
    if (list == doc.end() || !list->is_array()) continue;
    for (size_t i = 0; i < list->size(); ++i) {
      const auto& item = (*list)[i];
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      try {
        requireRegularFile(resolveInsideFolder(path, percentDecoded(uri)), "glTF buffer or image");
      } catch (const InputError& e) {
        fail<InputError>(path, ": ", std::string(kind, std::strlen(kind) - 1), " ", i, ": uri '", quoteInput(uri),
                         "': ", std::string(e.what()).substr(std::string(e.what()).rfind(": ") + 2));
      }
    }
  }
}

// tinygltf's messages and warnings come as lines, some empty; ours are one line each.
std::vector<std::string> nonEmptyLines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
    if (!trimmed(line).empty()) out.push_back(trimmed(line));
  return out;
}

}  // namespace

Scene importGltf(const std::string& path, const std::function<bool(double)>& progress) {
  ImportProgress report(progress, path);
  const std::string bytes = readInputFile(path, "glTF file");
  report.report(0.1);
  report.check();
  // tinygltf takes the size as an unsigned int: a larger file would be cut silently.
  if (bytes.size() > std::numeric_limits<unsigned>::max())
    fail<InputError>(path, ": ", bytes.size(), " bytes; tinygltf reads glTF files of at most 4 GiB");
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  const std::string_view json = jsonPart(bytes, binary);
  if (jsonDepth(json) > kMaxJsonDepth) fail<InputError>(path, ": JSON nested deeper than ", kMaxJsonDepth, " levels");

  checkExternalUris(path, json);
  FolderGuard guard{path, {}};
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keepImageBytes, nullptr);
  loader.SetFsCallbacks({guardedFileExists, keepPath, guardedReadWholeFile, refuseWrite, &guard});
  tinygltf::Model model;
  std::string err, warn;
  std::error_code ec;
  const std::string baseDir =
      std::filesystem::weakly_canonical(std::filesystem::absolute(path), ec).parent_path().string();
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const bool ok = binary
                      ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, unsigned(bytes.size()), baseDir)
                      : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir);
  if (!guard.refusal.empty()) throw InputError(guard.refusal);
  if (!ok) {
    std::string message;
    for (const std::string& line : nonEmptyLines(err)) message += (message.empty() ? "" : "; ") + line;
    fail<InputError>(path, ": ", message.empty() ? std::string("cannot read glTF file") : quoteInput(message, 300));
  }
  const bool textured = std::any_of(model.materials.begin(), model.materials.end(), [](const tinygltf::Material& m) {
    return m.pbrMetallicRoughness.baseColorTexture.index >= 0;
  });
  checkInstancedTriangles(path, model, textured);
  report.report(0.4);  // tinygltf parsed the file in one call, copying its buffers
  report.check();

  Scene scene = GltfReader(path, model, report).read();
  for (const std::string& line : nonEmptyLines(warn)) scene.warnings.push_back(path + ": " + quoteInput(line, 300));
  return scene;
}

}  // namespace vox
