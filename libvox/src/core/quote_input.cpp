#include "vox/core/quote_input.h"

#include <cstdio>

namespace vox {

std::string quoteInput(const std::string& text, size_t maxBytes) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (out.size() >= maxBytes) {
      out += "...";
      break;
    }
    const unsigned char c = static_cast<unsigned char>(text[i]);
    // Bytes of 0x80 and above pass: they are UTF-8 in file names and text users wrote.
    if (c >= 0x20 && c != 0x7f) {
      out += char(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return out;
}

}  // namespace vox
