// Outputs through a temporary file, fsync and rename (POSIX; Linux semantics for rename and fsync of a folder).
// Every write(), fsync() and close() result is checked: a full disk, a quota or RLIMIT_FSIZE (EFBIG) must end in
// OutputError with the old output untouched, never in a truncated file renamed over it.
#include "vox/io/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "vox/core/error.h"

namespace vox {

namespace {

// ---- Temporary files to remove on SIGINT/SIGTERM/SIGHUP ----
// The handler may only call async-signal-safe functions (POSIX.1-2017 2.4.3): unlink and _exit, reading fixed static
// storage through lock-free atomics. A slot is claimed (kClaimed) before its path is copied and published (kLive)
// only when complete, so the handler never reads a half-written path. The temporary file is created after it is
// published and unpublished after the rename or removal, so no moment exists where a file could be left behind; an
// unlink of an already renamed name fails harmlessly (the name carries our pid, nobody else creates it).
constexpr int kFree = 0, kClaimed = 1, kLive = 2;
constexpr size_t kSlots = 64, kPathBytes = 4096;  // PATH_MAX on Linux, with its terminating zero
static_assert(std::atomic<int>::is_always_lock_free);

struct Slot {
  std::atomic<int> state{kFree};
  char path[kPathBytes];
};
std::array<Slot, kSlots> gSlots;
// Folders of new files (TemporaryFolder), emptied and removed after the temporary files.
constexpr size_t kFolderSlots = 8;
std::array<Slot, kFolderSlots> gFolderSlots;

// Unlinks every entry of a folder of plain files, then the folder. Only system calls: getdents64 through syscall()
// because readdir() may allocate, which a signal handler must not.
void removeFolderInHandler(const char* path) {
  const int fd = ::open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buffer[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
      if (n <= 0) break;
      for (long at = 0; at < n;) {
        const auto* entry = reinterpret_cast<const dirent64*>(buffer + at);
        const char* name = entry->d_name;
        if (!(name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0)))) ::unlinkat(fd, name, 0);
        at += entry->d_reclen;
      }
    }
    ::close(fd);
  }
  ::rmdir(path);
}

extern "C" void removeTemporariesAndExit(int signal) {
  for (Slot& s : gSlots)
    if (s.state.load(std::memory_order_acquire) == kLive) ::unlink(s.path);
  for (Slot& s : gFolderSlots)
    if (s.state.load(std::memory_order_acquire) == kLive) removeFolderInHandler(s.path);
  ::_exit(128 + signal);
}

// ---- The handlers, installed only while a write is under way ----
// A library must leave the process as it found it: the handlers are installed when the first temporary file or
// folder is registered and the previous dispositions restored when the last one is released (a count under a
// mutex: writes run on several threads at once). Only a default disposition (which would end the process and leave
// the temporary behind) is replaced:
//  - a signal ignored (nohup, a background job of a non-interactive shell) stays ignored: the user asked for that;
//  - a handler of the host's own (Python's SIGINT handler, which raises KeyboardInterrupt) keeps working: the host
//    decides, and a write it abandons removes its temporary through the destructors (OutputFile, TemporaryFolder),
//    the old output whole. Replacing it with one that _exits would kill an interpreter on Ctrl-C.
constexpr std::array<int, 3> kSignals{SIGINT, SIGTERM, SIGHUP};
std::mutex gHandlersMutex;
int gRegistered = 0;                                      // temporary files and folders registered (gHandlersMutex)
std::array<struct sigaction, kSignals.size()> gPrevious;  // what each replaced disposition was
std::array<bool, kSignals.size()> gReplaced{};
bool gXfszIgnored = false;
struct sigaction gXfszPrevious {};

bool isDefault(const struct sigaction& a) { return !(a.sa_flags & SA_SIGINFO) && a.sa_handler == SIG_DFL; }

// Whether `sig` is still handled as we set it (`handler`): a disposition someone set since is theirs and stays.
bool stillOurs(int sig, void (*handler)(int)) {
  struct sigaction now {};
  return ::sigaction(sig, nullptr, &now) == 0 && !(now.sa_flags & SA_SIGINFO) && now.sa_handler == handler;
}

void acquireSignalHandlers() {
  std::lock_guard lock(gHandlersMutex);
  if (gRegistered++ > 0) return;
  for (size_t i = 0; i < kSignals.size(); ++i) {
    gReplaced[i] = false;
    struct sigaction old {};
    if (::sigaction(kSignals[i], nullptr, &old) != 0 || !isDefault(old)) continue;
    struct sigaction act {};
    act.sa_handler = removeTemporariesAndExit;
    sigfillset(&act.sa_mask);  // one handler at a time: a second signal must not interrupt the unlinks
    gReplaced[i] = ::sigaction(kSignals[i], &act, &gPrevious[i]) == 0;
  }
  // A write past RLIMIT_FSIZE then fails with EFBIG, which the writers report ("File too large") and which
  // removes the temporary file, instead of SIGXFSZ killing the process with the temporary file left behind.
  // sigaction, not signal(): glibc's signal() adds SA_RESTART and the signal to the mask, so restoring with it would
  // not give back the disposition found (the sanitizers' signal() does so too).
  struct sigaction xfsz {
  }, ignore{};
  ignore.sa_handler = SIG_IGN;
  gXfszIgnored = ::sigaction(SIGXFSZ, nullptr, &xfsz) == 0 && isDefault(xfsz) &&
                 ::sigaction(SIGXFSZ, &ignore, &gXfszPrevious) == 0;
}

void releaseSignalHandlers() {
  std::lock_guard lock(gHandlersMutex);
  if (--gRegistered > 0) return;
  for (size_t i = 0; i < kSignals.size(); ++i)
    if (gReplaced[i] && stillOurs(kSignals[i], removeTemporariesAndExit))
      ::sigaction(kSignals[i], &gPrevious[i], nullptr);
  if (gXfszIgnored && stillOurs(SIGXFSZ, SIG_IGN)) ::sigaction(SIGXFSZ, &gXfszPrevious, nullptr);
  gReplaced.fill(false);
  gXfszIgnored = false;
}

// Returns the slot index, or -1 when the path is too long or all slots are taken (the file is then not removed on a
// signal, which is the old behaviour, rather than refusing to write). A slot holds the handlers (above) until
// unpublishIn frees it; the handlers are installed before the path is published, and released after it is not.
template <size_t N>
int publishIn(std::array<Slot, N>& slots, const std::string& path) {
  if (path.size() >= kPathBytes) return -1;
  acquireSignalHandlers();
  for (size_t i = 0; i < N; ++i) {
    int expected = kFree;
    if (!slots[i].state.compare_exchange_strong(expected, kClaimed, std::memory_order_acquire)) continue;
    std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
    slots[i].state.store(kLive, std::memory_order_release);
    return int(i);
  }
  releaseSignalHandlers();
  return -1;
}

template <size_t N>
void unpublishIn(std::array<Slot, N>& slots, int slot) {
  if (slot < 0) return;
  slots[size_t(slot)].state.store(kFree, std::memory_order_release);
  releaseSignalHandlers();
}

int publishTemporary(const std::string& path) { return publishIn(gSlots, path); }

void unpublishTemporary(int slot) { unpublishIn(gSlots, slot); }

// ---- Checked I/O ----
// Writes all of [data, data + size) or returns the errno that stopped it (0 on success).
int writeAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, std::min<size_t>(size, size_t(1) << 30));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno;
    if (n == 0) return EIO;  // a regular file or device that accepts nothing would loop forever
    data += n;
    size -= size_t(n);
  }
  return 0;
}

// The temporary name keeps the final extension, since some tools and writers choose the format from it, and starts
// with a dot so that listings and globs skip it.
std::string temporaryName(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path p(path);
  const std::string stem = p.stem().string(), ext = p.extension().string();
  const std::string name =
      "." + stem + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(counter.fetch_add(1)) + ext;
  return (p.parent_path() / name).string();
}

std::string folderOf(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}

[[noreturn]] void failWrite(const std::string& path, int err) {
  fail<OutputError>(path, ": cannot write: ", std::strerror(err));
}

// Makes the rename itself durable. Best effort: the output is already in place, and some file systems refuse fsync
// on a folder (EINVAL).
void syncFolder(const std::string& path) {
  const int fd = ::open(folderOf(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

// A std::streambuf over a file descriptor that records the first write error instead of throwing, since the
// writers that use it (OpenMesh, tinygltf) do not expect exceptions from their stream.
class FdStreamBuf : public std::streambuf {
 public:
  explicit FdStreamBuf(const int& fd) : fd_(fd) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  int error() const { return error_; }
  bool flush() {
    const size_t n = size_t(pptr() - pbase());
    if (error_ == 0 && n > 0) error_ = writeAll(fd_, pbase(), n);
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return error_ == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!flush()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (size_t(n) < buffer_.size()) return std::streambuf::xsputn(s, n);
    // Large blocks (a glTF binary chunk) skip the copy.
    if (!flush()) return 0;
    error_ = writeAll(fd_, s, size_t(n));
    return error_ == 0 ? n : 0;
  }
  int sync() override { return flush() ? 0 : -1; }

 private:
  const int& fd_;
  int error_ = 0;
  std::array<char, 1 << 16> buffer_;
};

}  // namespace

struct OutputFile::Impl {
  int fd = -1;
  bool device = false;
  bool committed = false;
  std::string temp;
  int slot = -1;
  uint64_t flushed = 0;  // bytes whose writeback has been started (write())
  FdStreamBuf buffer{fd};
  std::ostream stream{&buffer};
};

namespace {

// Opens an existing character device or FIFO for writing in place. A FIFO is opened non-blocking first: with no
// reader open() fails with ENXIO at once instead of waiting forever (POSIX open(), O_NONBLOCK); then writes block
// as usual.
int openDevice(const std::string& path, bool fifo) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC | (fifo ? O_NONBLOCK : 0));
  if (fd < 0 && errno == ENXIO && fifo) fail<OutputError>(path, ": cannot write: FIFO has no reader");
  if (fd < 0) failWrite(path, errno);
  struct stat st {};
  // The node may have been replaced since it was looked at: never write into a regular file in place.
  if (::fstat(fd, &st) != 0 || !(S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode))) {
    ::close(fd);
    fail<OutputError>(path, ": cannot write: the file changed while it was opened");
  }
  if (fifo) ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return fd;
}

}  // namespace

OutputFile::OutputFile(const std::string& path) : path_(path), impl_(std::make_unique<Impl>()) {
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) fail<OutputError>(path, ": is a folder");
  if (exists && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode))) {
    impl_->fd = openDevice(path, S_ISFIFO(st.st_mode));
    impl_->device = true;
    return;
  }
  // A rename over a block device, socket or other node would replace it with a regular file.
  if (exists && !S_ISREG(st.st_mode))
    fail<OutputError>(path, ": cannot write: not a regular file, character device or FIFO");
  std::error_code ec;
  if (!std::filesystem::is_directory(folderOf(path), ec)) fail<OutputError>(path, ": folder does not exist");
  // O_EXCL: never write through a name someone else placed; a leftover of a crashed process that had our pid
  // only costs another name.
  for (int attempt = 0; impl_->fd < 0; ++attempt) {
    impl_->temp = temporaryName(path);
    impl_->slot = publishTemporary(impl_->temp);
    impl_->fd = ::open(impl_->temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (impl_->fd >= 0) break;
    const int err = errno;
    unpublishTemporary(impl_->slot);
    if (err != EEXIST || attempt == 100) failWrite(path, err);
  }
  // The new file keeps the permission bits of the one it replaces (as an in-place write would).
  if (exists) ::fchmod(impl_->fd, st.st_mode & 0777);
}

OutputFile::~OutputFile() {
  if (impl_->fd >= 0) ::close(impl_->fd);
  if (!impl_->committed && !impl_->device) {
    ::unlink(impl_->temp.c_str());
    unpublishTemporary(impl_->slot);
  }
}

bool OutputFile::isDevice() const { return impl_->device; }

std::ostream& OutputFile::stream() { return impl_->stream; }

void OutputFile::flush() {
  if (!impl_->buffer.flush()) failWrite(path_, impl_->buffer.error());
}

void OutputFile::write(std::string_view bytes) {
  VOX_CHECK(!impl_->committed);
  flush();  // bytes given to stream() before come first
  if (const int err = writeAll(impl_->fd, bytes.data(), bytes.size())) failWrite(path_, err);
  // Starts the kernel's writeback of each further 16 MiB, without waiting for it (SYNC_FILE_RANGE_WRITE only), so
  // that the disk works while the rest is encoded and commit()'s fsync finds less left to do. Durability is
  // unchanged: commit() still fsyncs before the rename.
  constexpr uint64_t kStep = uint64_t(16) << 20;
  Impl& f = *impl_;
  if (f.device || bytes.size() == 0) return;
  const off_t end = ::lseek(f.fd, 0, SEEK_CUR);
  if (end > 0 && uint64_t(end) - f.flushed >= kStep) {
    ::sync_file_range(f.fd, off_t(f.flushed), off_t(uint64_t(end) - f.flushed), SYNC_FILE_RANGE_WRITE);
    f.flushed = uint64_t(end);
  }
}

void OutputFile::commit() {
  VOX_CHECK(!impl_->committed);
  Impl& f = *impl_;
  flush();
  // fsync before the rename: otherwise a crash after it can leave an empty or partial file under the output's name
  // (delayed allocation on ext4, XFS). Devices and FIFOs have nothing to flush (fsync gives EINVAL).
  if (!f.device && ::fsync(f.fd) != 0) failWrite(path_, errno);
  const int fd = f.fd;
  f.fd = -1;
  // close() reports deferred write errors on NFS and some FUSE file systems; it is not retried on EINTR (Linux
  // releases the descriptor anyway).
  if (::close(fd) != 0 && errno != EINTR) failWrite(path_, errno);
  if (f.device) {
    f.committed = true;
    return;
  }
  if (::rename(f.temp.c_str(), path_.c_str()) != 0) failWrite(path_, errno);
  f.committed = true;
  unpublishTemporary(f.slot);
  syncFolder(path_);
}

TemporaryFolder::TemporaryFolder(const std::string& path, bool create) : path_(path), owner_(create) {
  // Published before it exists, like a temporary file: no moment where a signal could leave it behind. A folder
  // made by another rank is published without ownership: on a signal each rank removes what it can.
  slot_ = publishIn(gFolderSlots, path_);
  if (create && ::mkdir(path_.c_str(), 0777) != 0) {
    const int err = errno;
    unpublishIn(gFolderSlots, slot_);
    slot_ = -1;
    fail<OutputError>(path_, ": cannot create the folder: ", std::strerror(err));
  }
  if (create) syncFolder(path_);  // the files renamed into it are fsynced; its own entry must be too
}

void syncParentFolder(const std::string& path) { syncFolder(path); }

TemporaryFolder::~TemporaryFolder() {
  if (owner_) {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  keep();
}

void TemporaryFolder::keep() {
  unpublishIn(gFolderSlots, slot_);
  slot_ = -1;
  owner_ = false;
}

void writeFileAtomically(const std::string& path, std::string_view bytes) {
  OutputFile out(path);
  out.write(bytes);
  out.commit();
}

void checkOutputPath(const std::string& output, const std::vector<std::string>& inputs) {
  std::error_code ec;
  for (const std::string& input : inputs)
    if (std::filesystem::equivalent(input, output, ec) && !ec)
      fail<UsageError>(output, ": is the same file as the input ", input, " (writing it would destroy the input)");
  struct stat st {};
  if (::stat(output.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) fail<OutputError>(output, ": is a folder");
    if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) return;  // written in place, whatever its folder
    if (!S_ISREG(st.st_mode)) fail<OutputError>(output, ": cannot write: not a regular file, character device or FIFO");
  }
  const std::string folder = folderOf(output);
  if (!std::filesystem::is_directory(folder, ec)) fail<OutputError>(output, ": folder does not exist");
  if (::access(folder.c_str(), W_OK) != 0) fail<OutputError>(output, ": folder is not writable");
}

}  // namespace vox
