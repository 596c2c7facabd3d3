#include "vox/core/tool.h"

#include <cstdio>
#include <exception>
#include <new>

#include "vox/core/error.h"
#include "vox/io/input_file.h"

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

int runTool(const std::string& toolName, const std::function<int()>& body) {
  // One line, whatever the message holds: a library message can quote hostile input (a 10 MB data URI, control
  // bytes), so it is escaped and cut here as a last guard.
  auto report = [&](const char* message) {
    std::fprintf(stderr, "%s: error: %s\n", toolName.c_str(), quoteInput(message, kMaxMessageBytes).c_str());
  };
  try {
    return body();
  } catch (const OutputError& e) {
    report(e.what());
    return kExitCannotWrite;
  } catch (const UsageError& e) {
    report(e.what());
    return kExitUsage;
  } catch (const LimitError& e) {
    report(e.what());
    return kExitBadInput;
  } catch (const Error& e) {
    report(e.what());
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    // Every allocation that input drives is estimated and refused before it is made (LimitError); this is the
    // guard for what the estimates missed, so it says what to try.
    report("out of memory (the request was larger than estimated; try a smaller grid or --threads 1)");
    return kExitBadInput;
  } catch (const std::exception& e) {
    report(e.what());
    return kExitBadInput;
  }
}

}  // namespace vox
