// Placeholder until the fit subcommand lands; replaced by its issue.
#include "commands.hpp"

namespace tightbvh::cli {
void add_fit_command(CLI::App& /*app*/) {}
}  // namespace tightbvh::cli
