// Shared plumbing of the command-line tools: exit codes and the one place exceptions become messages.
#pragma once

#include <functional>
#include <string>

namespace vox {

enum ExitCode : int { kExitOk = 0, kExitUsage = 1, kExitBadInput = 2, kExitCannotWrite = 3 };

// Runs body(); turns vox::Error and std::exception into errorLine(toolName, ...) on stderr and STYLE.md exit codes.
int runTool(const std::string& toolName, const std::function<int()>& body);

// The one format of an error line, for every tool and MPI rank: "TOOL: error: MESSAGE\n", MESSAGE made one line
// (control bytes escaped as \xHH: a file name holding ESC or a newline cannot reach the terminal raw) and cut to
// about 600 bytes.
std::string errorLine(const std::string& toolName, const std::string& message);
// The same for "TOOL: warning: MESSAGE\n".
std::string warningLine(const std::string& toolName, const std::string& message);

// Inside a catch block: the exit code of the exception being handled (STYLE.md: UsageError 1, OutputError 3,
// anything else 2) and its message in `message`.
int currentExceptionExit(std::string& message);

// The version string printed by --version.
const char* versionString();

}  // namespace vox
