// Writing an output through a temporary file and a rename, so that readers never see a half-written file.
#pragma once

#include <functional>
#include <string>

namespace vox {

// Calls write(tempPath) to produce the file, then renames tempPath to `path`. On any exception the temporary
// file is removed and the exception propagates. Throws OutputError when the folder is not writable or the
// rename fails.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tempPath)>& write);

}  // namespace vox
