// The checked output writer: contents, the old output kept on every failure (full disk by RLIMIT_FSIZE and
// /dev/full, an abandoned write), no temporary left, devices and FIFOs written in place, signals, same-file refusal.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <future>
#include <sstream>
#include <thread>

#include "test_util.h"
#include "vox/io/atomic_file.h"
#include "vox/core/error.h"

namespace vox {
namespace {

using testing::readAll;

namespace fs = std::filesystem;

void writePlain(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Names in `dir` that look like our temporaries (.NAME.tmpPID_N.EXT).
std::vector<std::string> temporaries(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.starts_with(".") && name.find(".tmp") != std::string::npos) found.push_back(name);
  }
  return found;
}

// Runs body() in a child process (limits and signals must not touch the test process) and returns its exit status,
// or 1000 + the signal that killed it.
int inChild(const std::function<int()>& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    int code = 99;
    try {
      code = body();
    } catch (...) {
      code = 98;
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

// A 1 MB payload: past any small file-size limit and several stream buffers long.
std::string payload() {
  std::string s(1 << 20, '\0');
  for (size_t i = 0; i < s.size(); ++i) s[i] = char('a' + i % 23);
  return s;
}

TEST(AtomicFile, WritesAndReplacesKeepingPermissions) {
  testing::ScratchDir dir("atomic_replace");
  const std::string path = dir.file("out.bin");
  writeFileAtomically(path, "first");
  EXPECT_EQ(readAll(path), "first");
  ::chmod(path.c_str(), 0640);
  writeFileAtomically(path, payload());
  EXPECT_EQ(readAll(path), payload());
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  writeFileAtomically(path, "");
  EXPECT_EQ(fs::file_size(path), 0u);
  EXPECT_TRUE(temporaries(dir.path()).empty());
}

TEST(AtomicFile, StreamAndWriteKeepTheirOrder) {
  testing::ScratchDir dir("atomic_order");
  const std::string path = dir.file("out.txt");
  {
    OutputFile out(path);
    EXPECT_FALSE(out.isDevice());
    out.stream() << "a" << 1;
    out.write("b");
    out.stream() << payload();  // larger than the stream's buffer: written through
    out.write("c");
    out.commit();
  }
  EXPECT_EQ(readAll(path), "a1b" + payload() + "c");
}

TEST(AtomicFile, AbandonedWriteKeepsTheOldOutput) {
  testing::ScratchDir dir("atomic_abandon");
  const std::string path = dir.file("out.ply");
  writePlain(path, "old");
  {
    OutputFile out(path);
    out.write("new and partial");
    EXPECT_EQ(temporaries(dir.path()).size(), 1u);
    const std::string temp = temporaries(dir.path())[0];
    EXPECT_TRUE(temp.starts_with(".out.tmp") && temp.ends_with(".ply")) << temp;  // hidden, extension kept
  }                                                                               // no commit: as when a writer throws
  EXPECT_EQ(readAll(path), "old");
  EXPECT_TRUE(temporaries(dir.path()).empty());
}

// RLIMIT_FSIZE makes write() fail with EFBIG, like a full disk: every path of the writer must report it.
TEST(AtomicFile, FailedWritesKeepTheOldOutput) {
  testing::ScratchDir dir("atomic_efbig");
  const std::string path = dir.file("out.bin");
  writePlain(path, "old");
  for (int variant = 0; variant < 2; ++variant) {
    const int code = inChild([&] {
      std::signal(SIGXFSZ, SIG_IGN);
      const rlimit limit{64 << 10, 64 << 10};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      try {
        if (variant == 0) {
          writeFileAtomically(path, payload());
        } else {
          OutputFile out(path);
          for (int i = 0; i < 100; ++i) out.stream() << "line " << i << payload().substr(0, 4000) << '\n';
          out.commit();  // the stream's error surfaces here
        }
      } catch (const OutputError& e) {
        return std::string(e.what()).find("cannot write: File too large") != std::string::npos ? 3 : 4;
      }
      return 0;
    });
    EXPECT_EQ(code, 3) << "variant " << variant;
    EXPECT_EQ(readAll(path), "old");
    EXPECT_TRUE(temporaries(dir.path()).empty());
  }
}

TEST(AtomicFile, DevicesAreWrittenInPlace) {
  try {
    writeFileAtomically("/dev/full", "x");
    ADD_FAILURE() << "/dev/full accepted";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full: cannot write: No space left on device"), std::string::npos)
        << e.what();
  }
  OutputFile null("/dev/null");
  EXPECT_TRUE(null.isDevice());
  null.write(payload());
  null.commit();
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST(AtomicFile, FifoWithoutReaderIsRefusedAtOnce) {
  testing::ScratchDir dir("atomic_fifo");
  const std::string fifo = dir.file("pipe.ply");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(writeFileAtomically(fifo, "x"), OutputError);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));

  auto reader = std::async(std::launch::async, [&] { return readAll(fifo); });
  // The reader must have the FIFO open before the writer tries; retry until it has.
  for (int attempt = 0;; ++attempt) {
    try {
      writeFileAtomically(fifo, payload());
      break;
    } catch (const OutputError&) {
      ASSERT_LT(attempt, 500);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  EXPECT_EQ(reader.get(), payload());
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_TRUE(temporaries(dir.path()).empty());
}

TEST(AtomicFile, FoldersAndMissingFoldersAreRefused) {
  testing::ScratchDir dir("atomic_folder");
  EXPECT_THROW(writeFileAtomically(dir.path().string(), "x"), OutputError);
  EXPECT_THROW(writeFileAtomically(dir.file("missing/out.bin"), "x"), OutputError);
  EXPECT_THROW(checkOutputPath(dir.path().string(), {}), OutputError);
  EXPECT_THROW(checkOutputPath(dir.file("missing/out.bin"), {}), OutputError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(AtomicFile, SignalRemovesTheTemporary) {
  testing::ScratchDir dir("atomic_signal");
  const std::string path = dir.file("out.bin");
  writePlain(path, "old");
  for (int sig : {SIGINT, SIGTERM}) {
    const int code = inChild([&] {
      OutputFile out(path);
      out.write("partial");
      if (temporaries(dir.path()).size() != 1) return 5;
      ::raise(sig);
      return 6;  // not reached
    });
    EXPECT_EQ(code, 128 + sig);
    EXPECT_EQ(readAll(path), "old");
    EXPECT_TRUE(temporaries(dir.path()).empty());
  }
}

// A grid set's generation folder (TemporaryFolder): removed with its files by a signal, by destruction without
// keep(), and kept after keep().
TEST(AtomicFile, TemporaryFoldersGoWithASignalOrAFailure) {
  testing::ScratchDir dir("atomic_folder");
  const std::string folder = dir.file("gen");
  for (int sig : {SIGINT, SIGTERM}) {
    const int code = inChild([&] {
      TemporaryFolder f(folder, true);
      writeFileAtomically(folder + "/b_0_0_0.vgrid", "brick");
      OutputFile partial(folder + "/b_1_0_0.vgrid");
      partial.write("half");
      ::raise(sig);
      return 6;  // not reached
    });
    EXPECT_EQ(code, 128 + sig);
    EXPECT_FALSE(std::filesystem::exists(folder));
  }
  {
    TemporaryFolder f(folder, true);
    writeFileAtomically(folder + "/scene.vgrid", "scene");
    EXPECT_THROW(TemporaryFolder(folder, true), OutputError);  // a generation folder is always new
  }
  EXPECT_FALSE(std::filesystem::exists(folder));
  {
    TemporaryFolder f(folder, true);
    writeFileAtomically(folder + "/scene.vgrid", "scene");
    f.keep();
  }
  EXPECT_TRUE(std::filesystem::exists(folder + "/scene.vgrid"));
}

// A signal ignored when the process started (nohup, a background job) stays ignored.
TEST(AtomicFile, IgnoredSignalStaysIgnored) {
  testing::ScratchDir dir("atomic_ignored");
  const std::string path = dir.file("out.bin");
  const int code = inChild([&] {
    std::signal(SIGINT, SIG_IGN);
    OutputFile out(path);
    ::raise(SIGINT);
    out.write("done");
    out.commit();
    return 0;
  });
  EXPECT_EQ(code, 0);
  EXPECT_EQ(readAll(path), "done");
}

// The dispositions of the signals the writes handle, compared whole (handler, flags, mask).
struct Dispositions {
  std::vector<struct sigaction> actions;
  static Dispositions now() {
    Dispositions d;
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGXFSZ}) {
      struct sigaction a {};
      ::sigaction(sig, nullptr, &a);
      d.actions.push_back(a);
    }
    return d;
  }
  bool operator==(const Dispositions& o) const {
    for (size_t i = 0; i < actions.size(); ++i) {
      const struct sigaction &a = actions[i], &b = o.actions[i];
      // SA_RESTORER (0x04000000, Linux's <asm/signal.h>; glibc does not export it) is glibc's own: it sets it on
      // every sigaction(), restoring a never-set default included.
      if (a.sa_handler != b.sa_handler || (a.sa_flags ^ b.sa_flags) & ~0x04000000) return false;
      for (int sig = 1; sig < NSIG; ++sig)
        if (sigismember(&a.sa_mask, sig) != sigismember(&b.sa_mask, sig)) return false;
    }
    return true;
  }
};

void (*handlerOf(int sig))(int) {
  struct sigaction a {};
  ::sigaction(sig, nullptr, &a);
  return a.sa_handler;
}

std::atomic<int> hostSignals{0};
extern "C" void hostHandler(int) { hostSignals.fetch_add(1); }

// A library leaves the process as it found it (issue 45): after an OutputFile (committed or abandoned),
// writeFileAtomically and a TemporaryFolder, every disposition is what it was, whether default, ignored or the
// host's; during a write the default ones are replaced and the others are not.
TEST(AtomicFile, SignalDispositionsAreRestoredAfterEveryWrite) {
  testing::ScratchDir dir("atomic_dispositions");
  const std::string path = dir.file("out.bin"), folder = dir.file("gen");
  const int code = inChild([&] {
    struct sigaction host {};
    host.sa_handler = hostHandler;
    host.sa_flags = SA_RESTART;
    sigemptyset(&host.sa_mask);
    sigaddset(&host.sa_mask, SIGUSR1);
    // Each setting: SIGINT default, the host's, ignored; SIGTERM/SIGHUP/SIGXFSZ default, then others.
    for (int setting = 0; setting < 3; ++setting) {
      if (setting == 1) ::sigaction(SIGINT, &host, nullptr), ::sigaction(SIGHUP, &host, nullptr);
      if (setting == 2) std::signal(SIGINT, SIG_IGN), std::signal(SIGXFSZ, SIG_IGN);
      const Dispositions before = Dispositions::now();
      {
        OutputFile out(path);
        // During the write: a default disposition is replaced, the host's and an ignored one are not.
        if ((handlerOf(SIGTERM) == SIG_DFL) || handlerOf(SIGXFSZ) != SIG_IGN) return 10 + setting;
        if (setting == 1 && (handlerOf(SIGINT) != hostHandler || handlerOf(SIGHUP) != hostHandler)) return 20;
        if (setting == 2 && handlerOf(SIGINT) != SIG_IGN) return 21;
        {
          OutputFile second(path + "2");  // nested writes: restored only when the last one ends
          second.write("b");
          second.commit();
        }
        if (handlerOf(SIGTERM) == SIG_DFL) return 22;
        out.write("a");
        out.commit();
      }
      if (!(Dispositions::now() == before)) return 30 + setting;
      { OutputFile abandoned(path); }
      if (!(Dispositions::now() == before)) return 40 + setting;
      writeFileAtomically(path, "c");
      if (!(Dispositions::now() == before)) return 50 + setting;
      {
        TemporaryFolder f(folder, true);
        if (handlerOf(SIGTERM) == SIG_DFL) return 60 + setting;
        writeFileAtomically(folder + "/x", "x");
        f.keep();
        if (!(Dispositions::now() == before)) return 70 + setting;
      }
      std::filesystem::remove_all(folder);
      { TemporaryFolder removed(folder, true); }
      if (!(Dispositions::now() == before)) return 80 + setting;
    }
    return 0;
  });
  EXPECT_EQ(code, 0);
}

// Writes on several threads at once: the handlers stay while any is under way and go with the last.
TEST(AtomicFile, SignalDispositionsAreRestoredAfterConcurrentWrites) {
  testing::ScratchDir dir("atomic_dispositions_threads");
  const int code = inChild([&] {
    const Dispositions before = Dispositions::now();
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
      threads.emplace_back([&, t] {
        for (int n = 0; n < 200; ++n) writeFileAtomically(dir.file("t" + std::to_string(t)), "x");
      });
    for (auto& t : threads) t.join();
    return Dispositions::now() == before ? 0 : 1;
  });
  EXPECT_EQ(code, 0);
}

// A host's handler (Python's SIGINT) runs during a write instead of one that ends the process: the host decides,
// and a write it abandons keeps the old output and leaves no temporary.
TEST(AtomicFile, HostHandlerKeepsWorkingDuringAWrite) {
  testing::ScratchDir dir("atomic_host");
  const std::string path = dir.file("out.bin");
  writePlain(path, "old");
  const int code = inChild([&] {
    std::signal(SIGINT, hostHandler);
    {
      OutputFile out(path);
      out.write("partial");
      ::raise(SIGINT);
      if (hostSignals.load() != 1) return 2;
    }  // abandoned, as an exception raised by the host's handler would abandon it
    return handlerOf(SIGINT) == hostHandler ? 0 : 3;
  });
  EXPECT_EQ(code, 0);
  EXPECT_EQ(readAll(path), "old");
  EXPECT_TRUE(temporaries(dir.path()).empty());
}

TEST(AtomicFile, OutputThatIsAnInputIsRefused) {
  testing::ScratchDir dir("atomic_same");
  const std::string input = dir.file("scene.glb"), link = dir.file("link.glb"), hard = dir.file("hard.glb");
  writePlain(input, "scene");
  fs::create_symlink("scene.glb", link);
  fs::create_hard_link(input, hard);
  for (const std::string& output : {input, link, hard}) {
    EXPECT_THROW(checkOutputPath(output, {dir.file("other"), input}), UsageError) << output;
    EXPECT_THROW(checkOutputPath(input, {output}), UsageError) << output;
  }
  EXPECT_NO_THROW(checkOutputPath(dir.file("new.vgrid"), {input}));  // not there yet
  EXPECT_NO_THROW(checkOutputPath("/dev/null", {input}));
  EXPECT_EQ(readAll(input), "scene");
}

}  // namespace
}  // namespace vox
