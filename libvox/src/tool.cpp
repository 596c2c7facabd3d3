#include "vox/tool.h"

#include <cstdio>
#include <exception>
#include <new>

#include "vox/error.h"

namespace vox {

const char* versionString() {
#ifdef VOX_VERSION
  return VOX_VERSION;
#else
  return "unknown";
#endif
}

int runTool(const std::string& toolName, const std::function<int()>& body) {
  auto report = [&](const char* message) { std::fprintf(stderr, "%s: error: %s\n", toolName.c_str(), message); };
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
    report("out of memory");
    return kExitBadInput;
  } catch (const std::exception& e) {
    report(e.what());
    return kExitBadInput;
  }
}

}  // namespace vox
