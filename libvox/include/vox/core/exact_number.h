// A double as messages print a value the user gave or a file held (issue 45): the shortest text that reads back as
// the same double (std::to_chars), so 64.0000001 is not shown as "64" beside a limit of 64, nor -1e-300 or -0 as
// "-0.000000" (what std::to_string and a stream's default 6 digits make of them). "inf", "-inf", "nan" otherwise.
// Pass it to fail(...) for such values: fail streams a bare double with 6 significant digits.
#pragma once

#include <charconv>
#include <string>

namespace vox {

inline std::string exactNumber(double x) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof text, x).ptr);
}

}  // namespace vox
