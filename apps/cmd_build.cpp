// Placeholder until the build subcommand lands; replaced by its issue.
#include "commands.hpp"

namespace tightbvh::cli {
void add_build_command(CLI::App& /*app*/) {}
}  // namespace tightbvh::cli
