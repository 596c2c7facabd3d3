#include "vox/io/input_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "vox/core/error.h"
#include "vox/core/huge_pages.h"

namespace vox {

void requireRegularFile(const std::string& path, const char* what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) fail<InputError>(path, ": cannot open ", what, ": ", std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail<InputError>(path, ": is a folder, expected the ", what);
  if (!S_ISREG(st.st_mode))
    fail<InputError>(path, ": not a regular file (a device, FIFO or socket), expected the ", what);
}

namespace {

// The file opened for reading once it is known to be a regular file whose bytes the memory budget can hold (twice:
// a reader holds the bytes and what it makes of them). Opened once and checked again through the descriptor, so a
// file swapped after the check is still a regular file of known size when read.
struct OpenInput {
  std::FILE* file = nullptr;
  size_t size = 0;
};

OpenInput openInput(const std::string& path, const char* what) {
  requireRegularFile(path, what);
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) fail<InputError>(path, ": cannot open ", what, ": ", std::strerror(errno));
  struct stat st {};
  if (::fstat(::fileno(file), &st) != 0 || !S_ISREG(st.st_mode)) {
    std::fclose(file);
    fail<InputError>(path, ": not a regular file, not a ", what);
  }
  try {
    checkMemory(2.0 * double(st.st_size), path, std::string("reading this ") + what);
  } catch (...) {
    std::fclose(file);
    throw;
  }
  return {file, size_t(st.st_size)};
}

// Reads the opened file's `size` bytes into `into` and closes it; throws InputError when fewer can be read.
void readAll(const OpenInput& in, char* into, const std::string& path) {
  const size_t got = in.size == 0 ? 0 : std::fread(into, 1, in.size, in.file);
  const bool error = std::ferror(in.file) != 0;
  std::fclose(in.file);
  if (error || got != in.size) fail<InputError>(path, ": read error after ", got, " bytes");
}

}  // namespace

std::string readInputFile(const std::string& path, const char* what) {
  const OpenInput in = openInput(path, what);
  // Reserved on huge pages before the first touch: a large file's bytes otherwise cost a 4 KiB page fault per page.
  std::string bytes;
  try {
    bytes.reserve(in.size);
    adviseHugePages(bytes.data(), bytes.capacity());
    bytes.resize(in.size);
  } catch (...) {
    std::fclose(in.file);
    throw;
  }
  readAll(in, bytes.data(), path);
  return bytes;
}

HugeBuffer readInputBytes(const std::string& path, const char* what) {
  const OpenInput in = openInput(path, what);
  HugeBuffer bytes;
  try {
    bytes = HugeBuffer(in.size);
  } catch (...) {
    std::fclose(in.file);
    throw;
  }
  readAll(in, bytes.data(), path);
  return bytes;
}

std::string resolveInsideFolder(const std::string& referrer, const std::string& reference) {
  namespace fs = std::filesystem;
  const fs::path ref(reference);
  if (ref.is_absolute() || ref.has_root_name())
    fail<InputError>(referrer, ": '", quoteInput(reference),
                     "': absolute paths are refused (files must lie in the "
                     "folder of the file that names them)");
  return requireInsideFolder(referrer, (fs::absolute(referrer).parent_path() / ref).string());
}

std::string requireInsideFolder(const std::string& referrer, const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // Canonical forms resolve "..", "." and symbolic links, so neither can lead out.
  const fs::path folder = fs::weakly_canonical(fs::absolute(referrer).parent_path(), ec);
  const fs::path target = ec ? fs::path() : fs::weakly_canonical(fs::absolute(path), ec);
  if (ec) fail<InputError>(referrer, ": '", quoteInput(path), "': cannot resolve: ", ec.message());
  // Component by component: "/a/bc" is not inside "/a/b".
  auto t = target.begin();
  for (auto f = folder.begin(); f != folder.end(); ++f, ++t)
    if (t == target.end() || *f != *t)
      fail<InputError>(referrer, ": '", quoteInput(path, 80), "': lies outside the folder of ", referrer);
  return target.string();
}

}  // namespace vox
