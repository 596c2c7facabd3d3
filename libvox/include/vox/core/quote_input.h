// Untrusted text made safe to quote in a one-line message. In core: every stage's errors quote names and text
// from their input, and the tools' one error line (core/tool.h) quotes whole messages.
#pragma once

#include <cstddef>
#include <string>

namespace vox {

// `text` made safe to quote in a one-line message: control bytes (below 0x20, and 0x7f) escaped as \xHH, and cut
// to about `maxBytes` with "..." when longer.
std::string quoteInput(const std::string& text, size_t maxBytes = 40);

}  // namespace vox
