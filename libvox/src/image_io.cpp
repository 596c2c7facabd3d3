// OpenImageIO bridge (OIIO 2.4 on Debian 12): ImageOutput::create picks the writer from the file extension and
// returns null for an unknown one; open/write_image/close report failure by return value and geterror().
#include "vox/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "vox/atomic_file.h"
#include "vox/error.h"

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

void writeImage(const std::string& path, const Image& image) {
  if (!imageFormatSupported(path))
    fail<UsageError>(path, ": unknown image format (use an extension such as .png, .tga, .exr, .jpg)");
  const bool asFloat = imageFormatHoldsFloat(path);
  writeAtomically(path, [&](const std::string& temp) {
    auto out = OIIO::ImageOutput::create(temp);
    if (!out) fail<OutputError>(path, ": cannot create an image writer: ", OIIO::geterror());
    // Formats such as HDR want three channels; give what the writer accepts.
    uint32_t channels = image.channels;
    if (channels == 1 && !out->supports("channelformats") && extensionOf(path) == ".hdr") channels = 3;
    OIIO::ImageSpec spec(int(image.width), int(image.height), int(channels),
                         asFloat ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (!out->open(temp, spec)) fail<OutputError>(path, ": cannot write: ", out->geterror());
    const uint64_t count = uint64_t(image.width) * image.height;
    bool ok;
    if (asFloat) {
      std::vector<float> data(count * channels);
      for (uint64_t i = 0; i < count; ++i)
        for (uint32_t c = 0; c < channels; ++c)
          data[i * channels + c] = image.pixels[i * image.channels + std::min(c, image.channels - 1)];
      ok = out->write_image(OIIO::TypeDesc::FLOAT, data.data());
    } else {
      std::vector<unsigned char> data(count * channels);
      for (uint64_t i = 0; i < count; ++i)
        for (uint32_t c = 0; c < channels; ++c) {
          const float v = image.pixels[i * image.channels + std::min(c, image.channels - 1)];
          const float clamped = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
          data[i * channels + c] = static_cast<unsigned char>(std::lround(clamped * 255.0f));
        }
      ok = out->write_image(OIIO::TypeDesc::UINT8, data.data());
    }
    if (!ok) {
      const std::string err = out->geterror();
      out->close();
      fail<OutputError>(path, ": cannot write: ", err);
    }
    if (!out->close()) fail<OutputError>(path, ": cannot write: ", out->geterror());
  });
}

}  // namespace vox
