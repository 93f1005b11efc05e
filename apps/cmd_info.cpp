// tightbvh info MESH... [--json]: vertices, triangles, degenerate triangles, bounds.
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::cli {

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "print statistics of meshes");
  struct Args {
    std::vector<std::string> meshes;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("meshes", args->meshes, "mesh files (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->footer("Example:\n  tightbvh info meshes/elephant.off meshes/knot1.off");
  cmd->callback([args] {
    nlohmann::json out = nlohmann::json::array();
    for (const std::string& path : args->meshes) {
      // load_mesh validates; check_mesh() again is cheap and gives the statistics.
      const MeshStats s = check_mesh(load_mesh(path), path);
      const auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
      if (args->json) {
        out.push_back({{"mesh", path},
                       {"vertices", s.vertices},
                       {"triangles", s.triangles},
                       {"degenerate_triangles", s.degenerate_triangles},
                       {"bounds", {{"min", vec(s.bounds.min)}, {"max", vec(s.bounds.max)}}}});
      } else {
        const auto text = [](const Vec3& v) {
          std::ostringstream os;
          os << std::setprecision(9) << '(' << v.x() << ", " << v.y() << ", " << v.z() << ')';
          return os.str();
        };
        std::cout << path << ": " << s.vertices << " vertices, " << s.triangles << " triangles, "
                  << s.degenerate_triangles << " degenerate, bounds " << text(s.bounds.min) << " - "
                  << text(s.bounds.max) << '\n';
      }
    }
    if (args->json) std::cout << out.dump(2) << '\n';
  });
}

}  // namespace tightbvh::cli
