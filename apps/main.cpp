// The `tightbvh` command-line tool. Errors: one line on stderr, non-zero exit.
#include <exception>
#include <iostream>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"tightbvh: tight oriented-box hierarchies for collision detection"};
  app.require_subcommand(1);
  tightbvh::cli::add_info_command(app);
  tightbvh::cli::add_fit_command(app);
  tightbvh::cli::add_build_command(app);
  tightbvh::cli::add_collide_command(app);
  tightbvh::cli::add_distance_command(app);
  tightbvh::cli::add_view_command(app);
  tightbvh::cli::add_scene_command(app);
  tightbvh::cli::add_points_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error (CLI11's default adds a "Run with --help" line).
    std::cerr << "tightbvh: error: " << e.what() << " (see --help)\n";
    return e.get_exit_code() != 0 ? e.get_exit_code() : 2;
  } catch (const std::exception& e) {
    std::cerr << "tightbvh: error: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
