// OpenImageIO bridge for decoding textures (texture_decode.h), OIIO 2.4 as
// Debian 12 ships it. Quirks relied on:
// - ImageInput::create(name, false, nullptr, proxy) picks the reader from the
// name's extension only and opens
//   nothing; a reader that does not support "ioproxy" would open a real file of
//   that name, so it is refused before open. Every byte decoded is the
//   caller's, already read through input_file.h (folder and size checks).
// - open, read_image report failure by return value and geterror(); the JPEG
// reader turns libjpeg's fatal errors
//   into a failed read (its error manager longjmps back), it does not exit.
// - the PNG reader leaves libpng's default error handler in place, which prints
// "libpng error: ..." on stderr
//   before OIIO reports the failure: the library must not print, so PNG chunks
//   (lengths, CRCs, IEND) are checked here first, which refuses truncated and
//   corrupted files before libpng sees them.
#include "import/texture_decode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <vector>

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

std::string oiioError(const std::string& message) {
  std::string m = message.empty() ? OIIO::geterror() : message;
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
  const std::string fakeName = "texture" + ext;
  OIIO::Filesystem::IOMemReader proxy(bytes.data(), bytes.size());
  auto in = OIIO::ImageInput::create(fakeName, false, nullptr, &proxy);
  if (!in) fail<InputError>(where, ": no image reader for '", quoteInput(ext), "' files: ", oiioError(""));
  if (!in->supports("ioproxy")) fail<InputError>(where, ": '", quoteInput(ext), "' images cannot be read from memory");
  in->set_ioproxy(&proxy);
  // Colours as stored: OIIO would otherwise premultiply PNG's unassociated
  // alpha, blackening transparent texels.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::ImageSpec spec;
  if (!in->open(fakeName, spec, config)) fail<InputError>(where, ": cannot decode image: ", oiioError(in->geterror()));
  const int channels = spec.nchannels;
  if (spec.width <= 0 || spec.height <= 0 || spec.width > int(kMaxTextureSide) || spec.height > int(kMaxTextureSide))
    fail<InputError>(where, ": image size ", spec.width, "x", spec.height, " is not between 1 and ", kMaxTextureSide,
                     " on each side");
  if (spec.depth > 1) fail<InputError>(where, ": volume images are not textures");
  if (channels < 1 || channels > 64) fail<InputError>(where, ": image has ", channels, " channels");
  const size_t texels = size_t(spec.width) * size_t(spec.height);
  const bool isFloat = spec.format.basetype == OIIO::TypeDesc::FLOAT || spec.format.basetype == OIIO::TypeDesc::HALF ||
                       spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  const int keep = std::min(channels, 3);
  checkMemory(double(texels) * keep * (isFloat ? 4 + 1 : 1) + double(texels) * 3, where, "decoding the image");

  Texture tex;
  tex.name = name;
  tex.width = uint32_t(spec.width);
  tex.height = uint32_t(spec.height);
  tex.rgb.resize(texels * 3);
  std::vector<uint8_t> pixels;
  if (isFloat) {
    // Floating-point images hold linear light; textures store sRGB-encoded
    // bytes.
    std::vector<float> linear(texels * size_t(keep));
    if (!in->read_image(0, 0, 0, keep, OIIO::TypeDesc::FLOAT, linear.data()))
      fail<InputError>(where, ": cannot decode image: ", oiioError(in->geterror()));
    pixels.resize(linear.size());
    for (size_t i = 0; i < linear.size(); ++i) pixels[i] = uint8_t(std::lround(linearToSrgb(linear[i]) * 255));
  } else {
    pixels.resize(texels * size_t(keep));
    if (!in->read_image(0, 0, 0, keep, OIIO::TypeDesc::UINT8, pixels.data()))
      fail<InputError>(where, ": cannot decode image: ", oiioError(in->geterror()));
  }
  in->close();
  toRgb(pixels, keep, tex.rgb);
  return tex;
}

}  // namespace vox
