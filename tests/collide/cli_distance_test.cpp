// `tightbvh distance` and `tightbvh collide --margin`, run as a user would.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>

#include "../cli_runner.hpp"

namespace tightbvh {
namespace {

using test::CliRun;

std::string meshes() {
  const std::string dir = std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/";
  return dir + "knot1.off " + dir + "elephant.off";
}

// B moved along x by `dx` (knot1 and elephant are scaled to unit boxes).
std::string shifted(double dx) { return " --pose \"1 0 0 0 1 0 0 0 1 " + std::to_string(dx) + " 0 0\""; }

TEST(CliDistance, JsonSeparatedAndTouching) {
  const CliRun far = test::run_cli("distance " + meshes() + shifted(1.5) + " --fitter pca --json");
  ASSERT_EQ(far.status, 0) << far.err;
  const auto j = nlohmann::json::parse(far.out);
  const double d = j["distance"].get<double>();
  EXPECT_GT(d, 0.0);
  EXPECT_LT(d, 1.5);
  EXPECT_FALSE(j["beyond_upper_bound"].get<bool>());
  const auto a = j["point_a"], b = j["point_b"];
  double squared = 0;
  for (int k = 0; k < 3; ++k)
    squared += (a[k].get<double>() - b[k].get<double>()) * (a[k].get<double>() - b[k].get<double>());
  EXPECT_NEAR(std::sqrt(squared), d, 1e-12);
  EXPECT_EQ(j["triangles"].size(), 2u);
  EXPECT_GT(j["node_pairs"].get<int>(), 0);

  // The same query with an upper bound below the answer: "farther than".
  const CliRun bounded = test::run_cli("distance " + meshes() + shifted(1.5) + " --fitter pca --json --upper-bound " +
                                       std::to_string(0.5 * d));
  ASSERT_EQ(bounded.status, 0) << bounded.err;
  EXPECT_TRUE(nlohmann::json::parse(bounded.out)["beyond_upper_bound"].get<bool>());

  const CliRun touching = test::run_cli("distance " + meshes() + shifted(0.1) + " --fitter aabb");
  ASSERT_EQ(touching.status, 0) << touching.err;
  EXPECT_NE(touching.out.find("distance: 0\n"), std::string::npos) << touching.out;

  // collide --margin: no contact at the far pose, a hit with a margin just above the distance.
  const CliRun plain = test::run_cli("collide " + meshes() + shifted(1.5) + " --fitter pca --json");
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(plain.out)["hit"].get<bool>());
  const CliRun margin = test::run_cli("collide " + meshes() + shifted(1.5) +
                                      " --fitter pca --json --all-pairs --margin " + std::to_string(1.01 * d));
  ASSERT_EQ(margin.status, 0) << margin.err;
  const auto m = nlohmann::json::parse(margin.out);
  EXPECT_TRUE(m["hit"].get<bool>());
  EXPECT_NEAR(m["margin"].get<double>(), 1.01 * d, 1e-6);
}

TEST(CliDistance, BadInputIsOneLineAndNonZeroExit) {
  for (const std::string& args :
       {"distance " + meshes() + " --rel-error -1", "distance " + meshes() + " --upper-bound nan",
        "distance " + meshes() + " --pose \"1 0 0\"", "collide " + meshes() + " --margin -0.1",
        "distance " + std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/knot1.off /nonexistent.off"}) {
    const CliRun r = test::run_cli(args + " --fitter aabb");
    EXPECT_NE(r.status, 0) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}

// An OFF cube [-h, h]^3 (outward), without its last triangle when `open`, in a temporary file.
std::string cube_file(double h, bool open) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("tightbvh_cli_cube_" + std::to_string(::getpid()) + "_" + std::to_string(h) +
                     (open ? "_open" : "") + ".off");
  std::ofstream out(path);
  out << "OFF\n8 " << (open ? 11 : 12) << " 0\n";
  for (int i = 0; i < 8; ++i) out << ((i & 1) ? h : -h) << ' ' << ((i & 2) ? h : -h) << ' ' << ((i & 4) ? h : -h) << '\n';
  const char* faces[] = {"0 2 1", "1 2 3", "4 5 6", "5 7 6", "0 1 4", "1 5 4",
                         "2 6 3", "3 6 7", "0 4 2", "2 4 6", "1 3 5", "3 7 5"};
  for (int f = 0; f < (open ? 11 : 12); ++f) out << "3 " << faces[f] << '\n';
  return path.string();
}

TEST(CliSolid, CollideAndDistanceWithOneMeshInsideTheOther) {
  // knot1 (in a unit box) inside a cube of side 4: no surfaces touch.
  const std::string knot = std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/knot1.off", big = cube_file(2.0, false);
  const CliRun plain = test::run_cli("collide " + knot + " " + big + " --fitter aabb --json");
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(plain.out)["hit"].get<bool>());
  const CliRun solid = test::run_cli("collide " + knot + " " + big + " --fitter aabb --json --solid");
  ASSERT_EQ(solid.status, 0) << solid.err;
  const auto j = nlohmann::json::parse(solid.out);
  EXPECT_TRUE(j["hit"].get<bool>());
  EXPECT_EQ(j["inside"].get<std::string>(), "a_in_b");
  EXPECT_EQ(j["pair_count"].get<int>(), 0);
  const CliRun text = test::run_cli("collide " + big + " " + knot + " --fitter aabb --solid");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("hit: yes\ninside: B is inside A"), std::string::npos) << text.out;

  const CliRun d = test::run_cli("distance " + knot + " " + big + " --fitter aabb --solid --json");
  ASSERT_EQ(d.status, 0) << d.err;
  const auto dj = nlohmann::json::parse(d.out);
  EXPECT_EQ(dj["distance"].get<double>(), 0.0);
  EXPECT_EQ(dj["inside"].get<std::string>(), "a_in_b");
  const CliRun far = test::run_cli("distance " + knot + " " + big + " --fitter aabb --json");
  ASSERT_EQ(far.status, 0) << far.err;
  EXPECT_GT(nlohmann::json::parse(far.out)["distance"].get<double>(), 0.5);

  // An open mesh: one line naming the mesh and why, exit code 1.
  const std::string open = cube_file(2.0, true);
  for (const std::string command : {"collide", "distance"}) {
    const CliRun r = test::run_cli(command + " " + knot + " " + open + " --fitter aabb --solid");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("mesh B is not closed: 3 boundary edges"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  std::filesystem::remove(big);
  std::filesystem::remove(open);
}

TEST(CliSolid, SignedDistanceOfOverlappingCubes) {
  // A cube of side 1 and one of side 0.5 moved 0.6 along x: B's corners at x = 0.35 lie inside A,
  // 0.15 from its face x = 0.5; no corner of A lies inside B.
  const std::string big = cube_file(0.5, false), small = cube_file(0.25, false);
  const CliRun r = test::run_cli("distance " + big + " " + small + shifted(0.6) + " --fitter aabb --signed --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["distance"].get<double>(), -0.15, 1e-15);
  EXPECT_EQ(j["deepest"].get<std::string>(), "b_in_a");
  EXPECT_FALSE(j["penetration_lower_bound_is_zero"].get<bool>());
  EXPECT_EQ(j["point_b"][0].get<double>(), 0.35);
  EXPECT_NEAR(j["point_a"][0].get<double>(), 0.5, 1e-15);
  EXPECT_FALSE(j.contains("triangles"));
  // Face to face: 0, no vertex inside, the bound 0 and the intersection curve's length printed.
  const CliRun touch = test::run_cli("distance " + big + " " + small + shifted(0.75) + " --fitter aabb --signed");
  ASSERT_EQ(touch.status, 0) << touch.err;
  EXPECT_NE(touch.out.find("distance: 0\n"), std::string::npos) << touch.out;
  EXPECT_NE(touch.out.find("penetration bound: 0 (no vertex inside the other solid); intersection curve: "),
            std::string::npos)
      << touch.out;
  // Without --signed the overlap is distance 0.
  const CliRun plain = test::run_cli("distance " + big + " " + small + shifted(0.6) + " --fitter aabb --json");
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out)["distance"].get<double>(), 0.0);
  std::filesystem::remove(big);
  std::filesystem::remove(small);
}

}  // namespace
}  // namespace tightbvh
