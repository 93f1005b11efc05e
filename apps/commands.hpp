#pragma once
// Each subcommand of the `tightbvh` tool lives in its own cmd_*.cpp and registers itself here.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <string>

#include "tightbvh/build.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"
#include <string>

#include "tightbvh/pose.hpp"

namespace tightbvh::cli {

void add_info_command(CLI::App& app);      // cmd_info.cpp
void add_fit_command(CLI::App& app);       // cmd_fit.cpp
void add_build_command(CLI::App& app);     // cmd_build.cpp (build, inspect)
void add_collide_command(CLI::App& app);   // cmd_collide.cpp (--view: apps/view/)
void add_distance_command(CLI::App& app);  // cmd_distance.cpp
void add_view_command(CLI::App& app);      // cmd_view.cpp (apps/view/)
void add_scene_command(CLI::App& app);     // cmd_scene.cpp (scene files, scene_file.hpp)
void add_points_command(CLI::App& app);    // cmd_points.cpp (point queries, point_query.hpp)

// A finite number > 0, else "--leaf-size: must be a positive number, got '0'" (CLI11's
// PositiveNumber says so by printing DBL_MAX in full).
[[nodiscard]] inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) {
        double value = 0.0;
        if (CLI::detail::lexical_cast(text, value) && value > 0.0 && std::isfinite(value)) return std::string();
        return "must be a positive number, got '" + text + "'";
      },
      "POSITIVE");
}

// The library's pose parser (pose_text.hpp), with the option named in its messages (cmd_collide.cpp).
[[nodiscard]] Pose parse_pose_option(const std::string& text);

// Throws InputError naming the option and its text as given unless `value` is >= 0 and finite
// (or +infinity when `infinity_allowed`): checked before any mesh is loaded (cmd_collide.cpp).
void require_non_negative(const CLI::Option& option, double value, bool infinity_allowed = false);

// What the pair queries (collide, distance) start from: both meshes loaded, B's pose parsed, and
// both trees built with the same options (cmd_collide.cpp). A stays at the identity.
struct MeshPair {
  Fitter fitter;
  Mesh a, b;
  Pose pose_b;
  Tree ta, tb;
  double build_seconds = 0.0;  // both trees
};
[[nodiscard]] MeshPair load_pair(const std::string& mesh_a, const std::string& mesh_b, const std::string& pose,
                                 const std::string& fitter, std::uint32_t leaf_size, unsigned threads);

}  // namespace tightbvh::cli
