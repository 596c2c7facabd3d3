#include "vox/io/input_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>

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

struct CloseFile {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// The file opened for reading once it is known to be a regular file of at most maxBytes whose bytes the memory
// budget can hold (twice: a reader holds the bytes and what it makes of them). Opened once and checked again through
// the descriptor, so a file swapped after the check is still a regular file of known size when read. Closed by its
// handle on every path.
struct OpenInput {
  std::unique_ptr<std::FILE, CloseFile> file;
  size_t size = 0;
};

OpenInput openInput(const std::string& path, const char* what, size_t maxBytes) {
  requireRegularFile(path, what);
  OpenInput in{std::unique_ptr<std::FILE, CloseFile>(std::fopen(path.c_str(), "rb"))};
  if (!in.file) fail<InputError>(path, ": cannot open ", what, ": ", std::strerror(errno));
  struct stat st {};
  if (::fstat(::fileno(in.file.get()), &st) != 0 || !S_ISREG(st.st_mode))
    fail<InputError>(path, ": not a regular file, not a ", what);
  in.size = size_t(st.st_size);
  if (in.size > maxBytes)
    fail<InputError>(path, ": ", what, " is ", in.size, " bytes, more than the limit of ", maxBytes, " bytes");
  checkMemory(2.0 * double(st.st_size), path, std::string("reading this ") + what);
  return in;
}

// Reads the opened file's `size` bytes into `into`; throws InputError when fewer can be read.
void readAll(const OpenInput& in, char* into, const std::string& path) {
  const size_t got = in.size == 0 ? 0 : std::fread(into, 1, in.size, in.file.get());
  if (std::ferror(in.file.get()) != 0 || got != in.size) fail<InputError>(path, ": read error after ", got, " bytes");
}

}  // namespace

namespace {

// readAll, asking `progress` after every 32 MiB piece when there is one.
void readAllAsking(const OpenInput& in, char* data, const std::string& path,
                   const std::function<bool(double)>& progress) {
  if (!progress) {
    readAll(in, data, path);
    return;
  }
  constexpr size_t kPiece = size_t{32} << 20;
  for (size_t at = 0; at < in.size; at += kPiece) {
    const size_t want = std::min(kPiece, in.size - at);
    const size_t got = std::fread(data + at, 1, want, in.file.get());
    if (std::ferror(in.file.get()) != 0 || got != want)
      fail<InputError>(path, ": read error after ", at + got, " bytes");
    if (!progress(double(at + got) / double(in.size))) fail<Error>(path, ": reading cancelled");
  }
}

}  // namespace

std::string readInputFile(const std::string& path, const char* what, const std::function<bool(double)>& progress) {
  const OpenInput in = openInput(path, what, SIZE_MAX);
  // Reserved on huge pages before the first touch: a large file's bytes otherwise cost a 4 KiB page fault per page.
  std::string bytes;
  bytes.reserve(in.size);
  adviseHugePages(bytes.data(), bytes.capacity());
  bytes.resize(in.size);
  readAllAsking(in, bytes.data(), path, progress);
  return bytes;
}

HugeBuffer readInputBytes(const std::string& path, const char* what, size_t maxBytes,
                          const std::function<bool(double)>& progress) {
  const OpenInput in = openInput(path, what, maxBytes);
  HugeBuffer bytes(in.size);
  readAllAsking(in, bytes.data(), path, progress);
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
