// The OpenImageIO module (libvox_oiio.so; io/oiio_module.h says why it is apart). OIIO 2.4 as Debian 12 ships it.
// Quirks relied on:
// - ImageOutput::create picks the writer from the file extension and returns null for an unknown one;
//   ImageInput::create(name, false, nullptr, proxy) picks the reader from the name's extension only and opens
//   nothing; a reader that does not support "ioproxy" would open a real file of that name, so it is refused before
//   open (every byte decoded is the caller's, already read through input_file.h).
// - open, read_image, write_image and close report failure by return value and geterror(), except the JPEG
//   writer, whose libjpeg error handler calls exit(1) on a failed write: hence images are encoded in memory. The
//   JPEG reader turns libjpeg's fatal errors into a failed read (its error manager longjmps back).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "io/oiio_module.h"

namespace vox {
namespace {

std::string extensionOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

bool holdsFloat(const std::string& ext) {
  return ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".hdr" || ext == ".pfm";
}

bool canWrite(const std::string& path) {
  if (extensionOf(path).size() < 2) return false;
  auto out = OIIO::ImageOutput::create(path);
  OIIO::geterror();  // clear the message of a failed create
  return bool(out);
}

// Hands the pixels to an opened writer: 8 bits clamped to [0, 1] and rounded, or floats as they are. Returns
// false with `error` set when OpenImageIO fails.
bool writePixels(OIIO::ImageOutput& out, const std::string& name, const std::string& path, const Image& image,
                 std::string& error) {
  const bool asFloat = holdsFloat(extensionOf(path));
  // Formats such as HDR want three channels; give what the writer accepts.
  uint32_t channels = image.channels;
  if (channels == 1 && !out.supports("channelformats") && extensionOf(path) == ".hdr") channels = 3;
  OIIO::ImageSpec spec(int(image.width), int(image.height), int(channels),
                       asFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  if (asFloat && channels == 1) {
    // The one single-channel image is depth: named Z, the depth channel of OpenEXR's conventions that Blender's
    // compositor, Nuke and OpenImageIO itself (z_channel) recognise; OIIO would call it Y.
    spec.channelnames = {"Z"};
    spec.z_channel = 0;
  }
  if (!out.open(name, spec)) {
    error = out.geterror();
    return false;
  }
  const uint64_t count = uint64_t(image.width) * image.height;
  auto channel = [&](uint64_t i, uint32_t c) {
    return image.pixels[i * image.channels + std::min(c, image.channels - 1)];
  };
  bool ok;
  if (asFloat) {
    std::vector<float> data(count * channels);
    for (uint64_t i = 0; i < count; ++i)
      for (uint32_t c = 0; c < channels; ++c) data[i * channels + c] = channel(i, c);
    ok = out.write_image(OIIO::TypeDesc::FLOAT, data.data());
  } else {
    std::vector<unsigned char> data(count * channels);
    for (uint64_t i = 0; i < count; ++i)
      for (uint32_t c = 0; c < channels; ++c) {
        const float v = channel(i, c);
        const float clamped = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
        data[i * channels + c] = static_cast<unsigned char>(std::lround(clamped * 255.0f));
      }
    ok = out.write_image(OIIO::TypeDesc::UINT8, data.data());
  }
  if (!ok) error = out.geterror();
  const bool closed = out.close();
  if (ok && !closed) error = out.geterror();
  return ok && closed;
}

// The whole file in memory. Most OIIO 2.4 writers take an IOProxy (PNG, JPEG, TGA, BMP, EXR, TIFF, HDR, ...);
// they are given a name that cannot be opened, so a writer that ignored the proxy would fail rather than touch a
// real file. The others (SGI, ICO, FITS, HEIF, ...) write by name into a memfd, a file in memory.
std::string encode(const std::string& path, const Image& image, std::string& bytes) {
  OIIO::Filesystem::IOVecOutput proxy;  // outlives the writer, which may flush into it on destruction
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return "cannot create an image writer: " + OIIO::geterror();
  std::string error;
  if (out->supports("ioproxy")) {
    if (!out->set_ioproxy(&proxy)) return "cannot write: " + out->geterror();
    if (!writePixels(*out, "/nonexistent/vox-image" + extensionOf(path), path, image, error))
      return "cannot write: " + error;
    const std::vector<unsigned char>& buffer = proxy.buffer();
    bytes.assign(buffer.begin(), buffer.end());
    return "";
  }
  const int fd = ::memfd_create("vox-image", MFD_CLOEXEC);
  if (fd < 0) return std::string("cannot write: ") + std::strerror(errno);
  struct CloseFd {
    int fd;
    ~CloseFd() { ::close(fd); }
  } closeFd{fd};
  if (!writePixels(*out, "/proc/self/fd/" + std::to_string(fd), path, image, error)) return "cannot write: " + error;
  bytes.clear();
  char chunk[1 << 16];
  for (off_t at = 0;;) {
    const ssize_t n = ::pread(fd, chunk, sizeof chunk, at);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return std::string("cannot write: ") + std::strerror(errno);
    if (n == 0) return "";
    bytes.append(chunk, size_t(n));
    at += n;
  }
}

DecodeFailure decode(const std::string& bytes, const std::string& ext,
                     const std::function<int(const ImageShape&)>& accept, std::vector<uint8_t>& bytes8,
                     std::vector<float>& floats, std::string& detail) {
  const std::string fakeName = "texture" + ext;
  OIIO::Filesystem::IOMemReader proxy(bytes.data(), bytes.size());
  auto in = OIIO::ImageInput::create(fakeName, false, nullptr, &proxy);
  if (!in) return detail = OIIO::geterror(), DecodeFailure::NoReader;
  if (!in->supports("ioproxy")) return DecodeFailure::NoMemoryReader;
  in->set_ioproxy(&proxy);
  // Colours as stored: OIIO would otherwise premultiply PNG's unassociated alpha, blackening transparent texels.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::ImageSpec spec;
  if (!in->open(fakeName, spec, config)) return detail = in->geterror(), DecodeFailure::Corrupt;
  const auto base = spec.format.basetype;
  const bool isFloat = base == OIIO::TypeDesc::FLOAT || base == OIIO::TypeDesc::HALF || base == OIIO::TypeDesc::DOUBLE;
  const int keep = accept({spec.width, spec.height, spec.depth, spec.nchannels, isFloat});
  const size_t samples = size_t(spec.width) * size_t(spec.height) * size_t(keep);
  bool ok;
  if (isFloat) {
    floats.resize(samples);
    ok = in->read_image(0, 0, 0, keep, OIIO::TypeDesc::FLOAT, floats.data());
  } else {
    bytes8.resize(samples);
    ok = in->read_image(0, 0, 0, keep, OIIO::TypeDesc::UINT8, bytes8.data());
  }
  if (!ok) return detail = in->geterror(), DecodeFailure::Corrupt;
  in->close();
  return DecodeFailure::None;
}

}  // namespace
}  // namespace vox

extern "C" const vox::OiioModule* vox_oiio_module() {
  static const vox::OiioModule module{vox::kOiioModuleVersion, vox::canWrite, vox::encode, vox::decode};
  return &module;
}
