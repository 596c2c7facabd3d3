// Writing images through OpenImageIO (the bridge file is image_io.cpp; no OIIO type appears here).
#pragma once

#include <string>

#include "vox/core/image.h"

namespace vox {

// Whether OpenImageIO has a writer for the extension of `path` (.png .tga .exr .jpg .tif .bmp .hdr ...).
bool imageFormatSupported(const std::string& path);
// Whether that format stores float channels (EXR, TIFF, HDR, PFM); others get 8 bits per channel.
bool imageFormatHoldsFloat(const std::string& path);

// Writes `image` to `path` through a temporary file in the same folder (keeping the extension, since OpenImageIO
// picks the format from it) and a rename. Float formats get the values as they are; 8-bit formats get them clamped
// to [0, 1] and rounded. Throws UsageError for an unknown extension, OutputError when the file cannot be written
// (no partial file is left behind). A one-channel image (depth) is written to float formats as a channel named Z.
void writeImage(const std::string& path, const Image& image);

}  // namespace vox
