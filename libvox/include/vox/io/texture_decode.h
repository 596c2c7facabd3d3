// Decoding of texture images held in memory (glTF images, OBJ map_Kd files), behind the OpenImageIO bridge
// texture_decode.cpp. In io beside the OpenImageIO module (io/oiio_module.h), the one place that opens it; the
// importers call it.
#pragma once

#include <string>

#include "vox/core/texture.h"

namespace vox {

// Decodes the encoded image `bytes` (PNG, JPEG, BMP, GIF, TGA, OpenEXR, HDR, ...: whatever OpenImageIO reads from
// memory) into a Texture named `name` with Repeat wraps. The format is told by the bytes' signature, else by the
// extension of `name`. Grey images are spread over R, G, B; alpha is dropped; 16-bit images are rounded to 8 bits;
// floating-point images (linear light) are encoded to sRGB. Allocates only after checkMemory accepted
// width * height texels. Throws InputError "WHERE: why" (`where` names the file and image) for bytes that are no
// image OpenImageIO reads, corrupt data, or a side larger than kMaxTextureSide; LimitError over the memory budget.
Texture decodeTexture(const std::string& bytes, const std::string& name, const std::string& where);

}  // namespace vox
