// Shared plumbing of the command-line tools: exit codes and the one place exceptions become messages.
#pragma once

#include <functional>
#include <string>

namespace vox {

enum ExitCode : int { kExitOk = 0, kExitUsage = 1, kExitBadInput = 2, kExitCannotWrite = 3 };

// Runs body(); turns vox::Error and std::exception into "TOOL: error: MESSAGE" on stderr and STYLE.md exit codes.
int runTool(const std::string& toolName, const std::function<int()>& body);

// The version string printed by --version.
const char* versionString();

}  // namespace vox
