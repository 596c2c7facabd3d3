// Reading untrusted input files: only regular files, only inside the folder a scene names, never more bytes than
// memory allows. Shared by the importers and the grid reader so that each check exists once.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

// The budget these checks hold reads to, and the quoting their messages use, are core's (other stages use them too);
// included here for the readers, which use all of them together.
#include "vox/core/huge_buffer.h"
#include "vox/core/memory_budget.h"
#include "vox/core/quote_input.h"

namespace vox {

// Reads a whole regular file. Throws InputError naming `path` when it is missing, a folder, a FIFO or device
// (which could block forever or never end), unreadable, or larger than the memory budget allows (LimitError).
// `what` names the file's role in messages ("scene file", "grid file").
// `progress`, when given, is asked after every 32 MiB piece; returning false cancels (vox::Error "PATH: reading
// cancelled").
std::string readInputFile(const std::string& path, const char* what, const std::function<bool(double)>& progress = {});

// The same, into a buffer on huge pages, whole and not zeroed first (huge_buffer.h): for the large texts the
// importers parse (OBJ, PLY), where the string's page faults and TLB misses cost more than the parse. A file of more
// than maxBytes is refused before it is read: "PATH: WHAT is N bytes, more than the limit of M bytes".
// `progress` (may be empty) gets the fraction read after every 32 MiB; return false to cancel (throws vox::Error
// "PATH: reading cancelled"): a few hundred MB take tenths of a second, longer than Ctrl-C may wait.
HugeBuffer readInputBytes(const std::string& path, const char* what, size_t maxBytes = SIZE_MAX,
                          const std::function<bool(double)>& progress = {});

// Throws InputError unless `path` names a regular file (checked before any importer opens it).
void requireRegularFile(const std::string& path, const char* what);

// Resolves `reference` (a relative path written inside `referrer`, such as a glTF buffer uri or an OBJ mtllib)
// against the referrer's folder. Throws InputError naming the referrer when the reference is absolute or, after
// resolving "..", symbolic links included, leaves that folder.
std::string resolveInsideFolder(const std::string& referrer, const std::string& reference);
// The canonical form of `path` (absolute, or relative to the current folder) when it lies inside the folder of
// `referrer`; throws InputError naming the referrer otherwise.
std::string requireInsideFolder(const std::string& referrer, const std::string& path);

}  // namespace vox
