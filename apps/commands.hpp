#pragma once
// Each subcommand of the `tightbvh` tool lives in its own cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>
#include <string>

#include "tightbvh/pose.hpp"

namespace tightbvh::cli {

void add_info_command(CLI::App& app);      // cmd_info.cpp
void add_fit_command(CLI::App& app);       // cmd_fit.cpp
void add_build_command(CLI::App& app);     // cmd_build.cpp (build, inspect)
void add_collide_command(CLI::App& app);   // cmd_collide.cpp (--view: apps/view/)
void add_distance_command(CLI::App& app);  // cmd_distance.cpp
void add_view_command(CLI::App& app);      // cmd_view.cpp (apps/view/)

// The library's pose parser (pose_text.hpp), with the option named in its messages (cmd_collide.cpp).
[[nodiscard]] Pose parse_pose_option(const std::string& text);

}  // namespace tightbvh::cli
