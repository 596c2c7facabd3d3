#include "vox/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "vox/error.h"

namespace vox {

namespace {
// The temporary name keeps the final extension, because some writers (OpenImageIO, OpenMesh) choose the format
// from it.
std::string temporaryName(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path p(path);
  const std::string stem = p.stem().string(), ext = p.extension().string();
  const std::string name =
      "." + stem + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter.fetch_add(1)) + ext;
  return (p.parent_path() / name).string();
}
}  // namespace

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  namespace fs = std::filesystem;
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) fail<OutputError>(path, ": folder does not exist");
  if (fs::is_directory(path, ec)) fail<OutputError>(path, ": is a folder");
  const std::string temp = temporaryName(path);
  try {
    write(temp);
  } catch (...) {
    std::remove(temp.c_str());
    throw;
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(temp.c_str());
    fail<OutputError>(path, ": cannot write: ", std::strerror(err));
  }
}

}  // namespace vox
