// Exceptions thrown by libvox. The library never prints; tools catch vox::Error once and turn it into one line
// on stderr and an exit code (STYLE.md: 2 bad input, 3 cannot write output).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace vox {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Input that is malformed or out of range: scene files, grid files, option values. Message names file and place.
struct InputError : Error {
  using Error::Error;
};
// An output that cannot be written (directory missing, permission, disk full).
struct OutputError : Error {
  using Error::Error;
};
// Command-line options that are invalid or inconsistent (exit code 1).
struct UsageError : Error {
  using Error::Error;
};
// A request that is valid but cannot be met (grid too large for memory).
struct LimitError : Error {
  using Error::Error;
};

// Builds a message from streamable parts: fail<InputError>(path, ": line ", 3, ": bad number").
template <typename E = InputError, typename... Parts>
[[noreturn]] void fail(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  throw E(out.str());
}

}  // namespace vox

// Programmer errors: always checked, print both sides.
#define VOX_CHECK(cond)                                                                            \
  do {                                                                                             \
    if (!(cond)) ::vox::fail<std::logic_error>(__FILE__, ":", __LINE__, ": check failed: " #cond); \
  } while (0)
