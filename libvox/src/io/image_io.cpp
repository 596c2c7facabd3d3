// OpenImageIO bridge (OIIO 2.4 on Debian 12): ImageOutput::create picks the writer from the file extension and
// returns null for an unknown one; open/write_image/close report failure by return value and geterror(), except
// the JPEG writer, whose libjpeg error handler calls exit(1) on a failed write: hence images are encoded in memory.
#include "vox/io/image_io.h"

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

#include "vox/io/atomic_file.h"
#include "vox/core/error.h"

namespace vox {

namespace {
std::string extensionOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}
}  // namespace

bool imageFormatSupported(const std::string& path) {
  if (extensionOf(path).size() < 2) return false;
  auto out = OIIO::ImageOutput::create(path);
  OIIO::geterror();  // clear the message of a failed create
  return bool(out);
}

bool imageFormatHoldsFloat(const std::string& path) {
  const std::string ext = extensionOf(path);
  return ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".hdr" || ext == ".pfm";
}

namespace {

// Hands the pixels to an opened writer: 8 bits clamped to [0, 1] and rounded, or floats as they are. Returns
// false with `error` set when OpenImageIO fails.
bool writePixels(OIIO::ImageOutput& out, const std::string& name, const std::string& path, const Image& image,
                 std::string& error) {
  const bool asFloat = imageFormatHoldsFloat(path);
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
std::string encodeImage(const std::string& path, const Image& image) {
  OIIO::Filesystem::IOVecOutput proxy;  // outlives the writer, which may flush into it on destruction
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail<OutputError>(path, ": cannot create an image writer: ", OIIO::geterror());
  std::string error;
  if (out->supports("ioproxy")) {
    if (!out->set_ioproxy(&proxy)) fail<OutputError>(path, ": cannot write: ", out->geterror());
    if (!writePixels(*out, "/nonexistent/vox-image" + extensionOf(path), path, image, error))
      fail<OutputError>(path, ": cannot write: ", error);
    const std::vector<unsigned char>& bytes = proxy.buffer();
    return std::string(bytes.begin(), bytes.end());
  }
  const int fd = ::memfd_create("vox-image", MFD_CLOEXEC);
  if (fd < 0) fail<OutputError>(path, ": cannot write: ", std::strerror(errno));
  struct CloseFd {
    int fd;
    ~CloseFd() { ::close(fd); }
  } closeFd{fd};
  if (!writePixels(*out, "/proc/self/fd/" + std::to_string(fd), path, image, error))
    fail<OutputError>(path, ": cannot write: ", error);
  std::string bytes;
  char chunk[1 << 16];
  for (off_t at = 0;;) {
    const ssize_t n = ::pread(fd, chunk, sizeof chunk, at);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail<OutputError>(path, ": cannot write: ", std::strerror(errno));
    if (n == 0) return bytes;
    bytes.append(chunk, size_t(n));
    at += n;
  }
}

}  // namespace

void writeImage(const std::string& path, const Image& image) {
  if (!imageFormatSupported(path))
    fail<UsageError>(path, ": unknown image format (use an extension such as .png, .tga, .exr, .jpg)");
  // Encoded in memory first: the writers cannot meet a disk error there (libjpeg's handler would call exit(1), the
  // TGA and BMP writers ignore short writes), and the one checked writer below handles the disk.
  writeFileAtomically(path, encodeImage(path, image));
}

}  // namespace vox
