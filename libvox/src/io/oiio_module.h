// OpenImageIO lives in a module of its own, libvox_oiio.so next to the executable, opened on first use: linked into
// the tools it pulled about 260 shared libraries (OpenCV, GDAL, FFmpeg, DCMTK, ...) into every start, half a second
// of `vox-voxelize --help`, although only texture decoding and image writing need it. Only plain data and strings
// cross the boundary: errors come back as text, the callers (texture_decode.cpp, image_io.cpp) phrase them.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vox/core/image.h"

namespace vox {

struct ImageShape {
  int width = 0, height = 0, depth = 1, channels = 0;
  bool isFloat = false;  // float, half or double samples: linear light
};

enum class DecodeFailure : uint8_t { None, NoReader, NoMemoryReader, Corrupt };

struct OiioModule {
  uint32_t version = 0;  // kOiioModuleVersion of the build that made the module
  // Whether OpenImageIO has a writer for the extension of `path`.
  bool (*canWrite)(const std::string& path) = nullptr;
  // Encodes `image` in the format of `path`'s extension into `bytes`; returns "" or what went wrong.
  std::string (*encode)(const std::string& path, const Image& image, std::string& bytes) = nullptr;
  // Decodes `bytes` read as format `ext` (".png"): `accept(shape)` sees the image's shape before any pixel is read
  // (it may throw) and returns how many channels to keep; they land in `floats` (isFloat) or `bytes8`. `detail`
  // gets OpenImageIO's message on failure.
  DecodeFailure (*decode)(const std::string& bytes, const std::string& ext,
                          const std::function<int(const ImageShape&)>& accept, std::vector<uint8_t>& bytes8,
                          std::vector<float>& floats, std::string& detail) = nullptr;
};

inline constexpr uint32_t kOiioModuleVersion = 1;

// The module, opened once (thread-safe). Throws vox::Error naming the file when it is missing or from another build.
const OiioModule& oiioModule();

}  // namespace vox

// The module's one entry point.
extern "C" const vox::OiioModule* vox_oiio_module();
