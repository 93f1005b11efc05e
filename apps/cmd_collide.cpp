// Placeholder until the collide subcommand lands; replaced by its issue.
#include "commands.hpp"

namespace tightbvh::cli {
void add_collide_command(CLI::App& /*app*/) {}
}  // namespace tightbvh::cli
