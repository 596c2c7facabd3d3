// Texture decoding: the checks and the conversion here, OpenImageIO's reading in its module (io/oiio_module.h).
// The PNG reader leaves libpng's default error handler in place, which prints "libpng error: ..." on stderr
// before OIIO reports the failure: the library must not print, so PNG chunks (lengths, CRCs, IEND) are checked here
// first, which refuses truncated and corrupted files before libpng sees them.
#include "vox/io/texture_decode.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <vector>

#include "io/oiio_module.h"
#include "vox/core/error.h"
#include "vox/io/input_file.h"

namespace vox {
namespace {

// The extension OpenImageIO should read `bytes` as: from the signature where it
// is unambiguous, else the name's.
std::string formatExtension(const std::string& bytes, const std::string& name) {
  auto startsWith = [&](const char* magic, size_t n) {
    return bytes.size() >= n && std::memcmp(bytes.data(), magic, n) == 0;
  };
  if (startsWith("\x89PNG", 4)) return ".png";
  if (startsWith("\xFF\xD8\xFF", 3)) return ".jpg";
  if (startsWith("GIF8", 4)) return ".gif";
  if (startsWith("BM", 2)) return ".bmp";
  if (startsWith("\x76\x2F\x31\x01", 4)) return ".exr";
  if (startsWith("#?", 2)) return ".hdr";
  std::string ext = std::filesystem::path(name).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// PNG's CRC-32 (ISO 3309, as in the PNG specification's annex D), over a
// chunk's type and data.
uint32_t pngCrc(const unsigned char* p, size_t n) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

// Walks the chunks of a PNG: each must lie inside the bytes with a matching
// CRC, up to IEND.
void checkPngChunks(const std::string& bytes, const std::string& where) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  auto be32 = [&](size_t at) {
    return uint32_t(p[at]) << 24 | uint32_t(p[at + 1]) << 16 | uint32_t(p[at + 2]) << 8 | p[at + 3];
  };
  size_t at = 8;  // after the signature
  while (true) {
    if (bytes.size() - at < 12) fail<InputError>(where, ": PNG truncated at byte ", bytes.size(), " (no IEND chunk)");
    const uint32_t length = be32(at);
    if (length > bytes.size() - at - 12)
      fail<InputError>(where, ": PNG chunk at byte ", at, " of ", length, " bytes runs past the end (", bytes.size(),
                       " bytes)");
    if (pngCrc(p + at + 4, size_t(length) + 4) != be32(at + 8 + length))
      fail<InputError>(where, ": PNG chunk at byte ", at, ": CRC mismatch (corrupt file)");
    const bool end = std::memcmp(p + at + 4, "IEND", 4) == 0;
    at += size_t(length) + 12;
    if (end) return;
  }
}

std::string oiioError(std::string m) {
  while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
  return quoteInput(m.empty() ? std::string("unknown error") : m, 160);
}

// Texel channels to RGB: grey (and grey + alpha) spread, alpha dropped.
void toRgb(const std::vector<uint8_t>& pixels, int channels, std::vector<uint8_t>& rgb) {
  const size_t n = rgb.size() / 3;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &pixels[i * size_t(channels)];
    rgb[3 * i] = p[0];
    rgb[3 * i + 1] = channels >= 3 ? p[1] : p[0];
    rgb[3 * i + 2] = channels >= 3 ? p[2] : p[0];
  }
}

}  // namespace

Texture decodeTexture(const std::string& bytes, const std::string& name, const std::string& where) {
  const std::string ext = formatExtension(bytes, name);
  if (ext.empty()) fail<InputError>(where, ": unknown image format (no known signature or extension)");
  if (ext == ".png") checkPngChunks(bytes, where);
  ImageShape shape;
  int keep = 0;
  auto accept = [&](const ImageShape& seen) {
    shape = seen;
    if (shape.width <= 0 || shape.height <= 0 || shape.width > int(kMaxTextureSide) ||
        shape.height > int(kMaxTextureSide))
      fail<InputError>(where, ": image size ", shape.width, "x", shape.height, " is not between 1 and ",
                       kMaxTextureSide, " on each side");
    if (shape.depth > 1) fail<InputError>(where, ": volume images are not textures");
    if (shape.channels < 1 || shape.channels > 64) fail<InputError>(where, ": image has ", shape.channels, " channels");
    const double texels = double(shape.width) * double(shape.height);
    keep = std::min(shape.channels, 3);
    checkMemory(texels * keep * (shape.isFloat ? 4 + 1 : 1) + texels * 3, where, "decoding the image");
    return keep;
  };
  std::vector<uint8_t> pixels;
  std::vector<float> linear;
  std::string detail;
  switch (oiioModule().decode(bytes, ext, accept, pixels, linear, detail)) {
    case DecodeFailure::None:
      break;
    case DecodeFailure::NoReader:
      fail<InputError>(where, ": no image reader for '", quoteInput(ext), "' files: ", oiioError(detail));
    case DecodeFailure::NoMemoryReader:
      fail<InputError>(where, ": '", quoteInput(ext), "' images cannot be read from memory");
    case DecodeFailure::Corrupt:
      fail<InputError>(where, ": cannot decode image: ", oiioError(detail));
  }
  Texture tex;
  tex.name = name;
  tex.width = uint32_t(shape.width);
  tex.height = uint32_t(shape.height);
  tex.rgb.resize(size_t(shape.width) * size_t(shape.height) * 3);
  if (shape.isFloat) {
    // Floating-point images hold linear light; textures store sRGB-encoded bytes.
    pixels.resize(linear.size());
    for (size_t i = 0; i < linear.size(); ++i) pixels[i] = uint8_t(std::lround(linearToSrgb(linear[i]) * 255));
  }
  toRgb(pixels, keep, tex.rgb);
  return tex;
}

}  // namespace vox
