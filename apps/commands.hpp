#pragma once
// Each subcommand of the `tightbvh` tool lives in its own cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>

namespace tightbvh::cli {

void add_info_command(CLI::App& app);

}  // namespace tightbvh::cli
