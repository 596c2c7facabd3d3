// The checked output writer: contents, the old output kept on every failure (full disk by RLIMIT_FSIZE and
// /dev/full, an abandoned write), no temporary left, devices and FIFOs written in place, signals, same-file refusal.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

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
