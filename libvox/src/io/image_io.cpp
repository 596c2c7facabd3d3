// Image writing: OpenImageIO encodes in memory (in its module, io/oiio_module.h), the one checked writer of
// atomic_file.h handles the disk.
#include "vox/io/image_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "io/oiio_module.h"
#include "vox/core/error.h"
#include "vox/io/atomic_file.h"

namespace vox {

bool imageFormatSupported(const std::string& path) { return oiioModule().canWrite(path); }

bool imageFormatHoldsFloat(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".hdr" || ext == ".pfm";
}

void writeImage(const std::string& path, const Image& image) {
  if (!imageFormatSupported(path))
    fail<UsageError>(path, ": unknown image format (use an extension such as .png, .tga, .exr, .jpg)");
  // Encoded in memory first: the writers cannot meet a disk error there (libjpeg's handler would call exit(1), the
  // TGA and BMP writers ignore short writes), and the one checked writer below handles the disk.
  std::string bytes;
  const std::string error = oiioModule().encode(path, image, bytes);
  if (!error.empty()) fail<OutputError>(path, ": ", error);
  writeFileAtomically(path, bytes);
}

}  // namespace vox
