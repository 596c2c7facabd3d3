#include "vox/core/tool.h"

#include <cstdio>
#include <exception>
#include <new>

#include "vox/core/error.h"
#include "vox/core/quote_input.h"

namespace vox {

const char* versionString() {
#ifdef VOX_VERSION
  return VOX_VERSION;
#else
  return "unknown";
#endif
}

namespace {
constexpr size_t kMaxMessageBytes = 600;
}  // namespace

std::string errorLine(const std::string& toolName, const std::string& message) {
  // One line, whatever the message holds: a library message can quote hostile input (a 10 MB data URI, control
  // bytes), so it is escaped and cut here as a last guard.
  return toolName + ": error: " + quoteInput(message, kMaxMessageBytes) + "\n";
}

std::string warningLine(const std::string& toolName, const std::string& message) {
  return toolName + ": warning: " + quoteInput(message, kMaxMessageBytes) + "\n";
}

int currentExceptionExit(std::string& message) {
  try {
    throw;
  } catch (const OutputError& e) {
    message = e.what();
    return kExitCannotWrite;
  } catch (const UsageError& e) {
    message = e.what();
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    // Every allocation that input drives is estimated and refused before it is made (LimitError); this is the
    // guard for what the estimates missed, so it says what to try.
    message = "out of memory (the request was larger than estimated; try a smaller grid or --threads 1)";
    return kExitBadInput;
  } catch (const std::exception& e) {
    message = e.what();  // InputError, LimitError and the rest: bad input
    return kExitBadInput;
  } catch (...) {
    message = "unknown error";
    return kExitBadInput;
  }
}

int runTool(const std::string& toolName, const std::function<int()>& body) {
  try {
    return body();
  } catch (...) {
    std::string message;
    const int code = currentExceptionExit(message);
    std::fputs(errorLine(toolName, message).c_str(), stderr);
    return code;
  }
}

}  // namespace vox
