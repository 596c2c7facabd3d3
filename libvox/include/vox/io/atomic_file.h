// Writing an output so that a failure (full disk, signal, error) never leaves a half-written file nor loses the old
// one: bytes go to a hidden temporary file in the output's folder, which is flushed to disk and renamed over the
// output. A character device or FIFO named as output is written straight into instead (a rename would replace the
// node with a regular file); any other file that is not a regular file is refused.
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace vox {

// One output being written. The constructor opens the temporary file (`.NAME.tmpPID_N.EXT` beside `path`) or the
// device; write() and stream() add bytes; commit() makes them the output. Destroying an uncommitted OutputFile
// removes the temporary file, so an exception anywhere leaves the old output as it was. While the temporary file
// exists its name sits in a registry that a SIGINT/SIGTERM/SIGHUP handler unlinks before it ends the process with
// _exit(128 + signal). That handler is installed only while a temporary file or folder is registered, and only for
// a signal whose disposition is the default one (SIGXFSZ is ignored likewise); the previous dispositions are
// restored when the last registration ends. A signal the process ignores stays ignored, and a handler of the host's
// own (Python's SIGINT, raising KeyboardInterrupt) stays in place: the host then ends the write by its exception
// path and the destructors remove the temporary.
// @throw OutputError "PATH: cannot write: REASON" from every member when the output cannot be written.
class OutputFile {
 public:
  explicit OutputFile(const std::string& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Appends bytes, checking every write().
  void write(std::string_view bytes);
  // A buffered stream into the same file, for writers that take a std::ostream. A failed write does not throw from
  // inside the writer (writers are not exception-safe); it is recorded and reported by commit().
  std::ostream& stream();
  // Writes out what stream() holds; throws the first write error the stream met.
  void flush();
  // Flushes the stream, fsyncs and closes the file, renames it over the output and fsyncs the folder.
  void commit();

  const std::string& path() const { return path_; }
  // Whether bytes go straight into a character device or FIFO (no temporary file, no rename).
  bool isDevice() const;

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

// A folder of new files that becomes an output only when something names it (a grid set's generation folder, named
// by its manifest): created here, and removed with the files in it by the destructor unless keep() was called, and
// by the SIGINT/SIGTERM/SIGHUP handler of OutputFile while it is registered (until keep() or destruction, with the
// same rules for installing and restoring the handlers). Holds files only, no subfolders.
// @throw OutputError "PATH: cannot create the folder: REASON" from the constructor when `create` and mkdir fails
// (EEXIST included: the folder must be new, so that nothing in it belongs to anyone else).
class TemporaryFolder {
 public:
  // `create`: make the folder (it must not exist). Otherwise it was made by another process (an MPI rank) and is
  // only registered for removal on a signal; the destructor then leaves it to its maker.
  TemporaryFolder(const std::string& path, bool create);
  ~TemporaryFolder();
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;

  // The folder stays: it is no longer removed on destruction or signal.
  void keep();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int slot_ = -1;
  bool owner_ = false;
};

// Makes the entry of `path` in its folder durable (fsync of the folder): after creating a folder whose files an
// output will name. Best effort, like the folder fsync of OutputFile::commit.
void syncParentFolder(const std::string& path);

// Writes `bytes` to `path` through an OutputFile (see above).
// @throw OutputError when the output cannot be written; the old output is then untouched.
void writeFileAtomically(const std::string& path, std::string_view bytes);

// Calls write(tempPath) to produce the file with a writer that only takes a path, then flushes it to disk and
// renames it over `path`. On any exception the temporary file is removed and the exception propagates. Prefer
// OutputFile: writers given a path rarely check their writes.
// @throw OutputError when the folder is not writable, the output is not a regular file, or flush or rename fail.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tempPath)>& write);

// Checks an output path before any input is read, so a bad output costs nothing:
//  - UsageError when `output` is the same file as one of `inputs` (std::filesystem::equivalent: also through
//    symlinks and hard links), since writing it would destroy the input;
//  - OutputError when its folder does not exist or it exists but is neither a regular file, a character device
//    nor a FIFO.
void checkOutputPath(const std::string& output, const std::vector<std::string>& inputs);

}  // namespace vox
