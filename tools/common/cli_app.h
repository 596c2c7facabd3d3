// CLI11 parsing with STYLE.md exit codes, --quiet, --threads and --version: for the files that build or parse a
// CLI::App (each tool's main.cpp and options.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <string>

#include "cli.h"
#include "vox/core/tool.h"

namespace vox::cli {

inline void addCommonOptions(CLI::App& app, CommonOptions& common) {
  app.set_version_flag("--version", std::string("libvox ") + versionString());
  app.add_flag("-q,--quiet", common.quiet, "No progress bar or warnings on stderr");
  app.add_option("--threads", common.threads, "Worker threads (default: all cores)")->check(CLI::Range(1u, 4096u));
}

// Parses argv; returns an exit code when the tool should stop now (help, version: 0; bad usage: 1).
inline std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error; --help is named in it.
    std::fprintf(stderr, "%s: error: %s (see --help)\n", app.get_name().c_str(), e.what());
    return kExitUsage;
  }
  return std::nullopt;
}

}  // namespace vox::cli
