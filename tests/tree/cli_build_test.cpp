// `tightbvh build` and `tightbvh inspect`, run as a user would (popen of the real binary).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include "../cli_runner.hpp"
#include "build_test_util.hpp"

namespace tightbvh {
namespace {

using test::CliRun;

CliRun run(const std::string& args) { return test::run_cli(args); }

std::string mesh(const char* name) { return (test::source_dir() / "meshes" / name).string(); }
std::string temp(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("tightbvh_cli_build_test_") + name)).string();
}

std::size_t count_lines(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) ++n;
  return n;
}

TEST(CliBuild, JsonStatsSaveAndInspect) {
  const std::string tree = temp("knot.tree");
  const CliRun b = run("build " + mesh("knot1.off") + " --fitter pca --split median --leaf-size 25 --threads 2 -o " +
                    tree + " --json --validate");
  ASSERT_EQ(b.status, 0) << b.err;
  const auto j = nlohmann::json::parse(b.out);
  EXPECT_EQ(j["triangles"], 6400);
  EXPECT_EQ(j["leaves"], 256);  // median halving, leaf size 25: 6400 = 256 * 25
  EXPECT_EQ(j["nodes"], 511);
  EXPECT_EQ(j["depth"]["max"], 8);
  EXPECT_EQ(j["depth"]["min"], 8);
  EXPECT_EQ(j["leaf_triangles"]["max"], 25);
  EXPECT_EQ(j["bytes"], 511 * 68 + 6400 * 4);
  EXPECT_EQ(j["volume_per_level"].size(), 9u);
  EXPECT_GT(j["sum_volume"].get<double>(), 0.0);
  EXPECT_GE(j["seconds"].get<double>(), 0.0);
  EXPECT_EQ(j["valid"], true);

  const CliRun i = run("inspect " + tree + " --json --mesh " + mesh("knot1.off"));
  ASSERT_EQ(i.status, 0) << i.err;
  const auto k = nlohmann::json::parse(i.out);
  EXPECT_EQ(k["nodes"], j["nodes"]);
  EXPECT_EQ(k["volume_per_level"], j["volume_per_level"]);
  EXPECT_EQ(k["sum_volume"], j["sum_volume"]);
  EXPECT_EQ(k["valid"], true);

  const CliRun text = run("inspect " + tree);
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("nodes 511,"), std::string::npos) << text.out;

  // The tree of another mesh does not validate.
  const CliRun wrong = run("inspect " + tree + " --mesh " + mesh("elephant.off"));
  EXPECT_NE(wrong.status, 0);
  EXPECT_NE(wrong.err.find("invalid"), std::string::npos) << wrong.err;
  std::filesystem::remove(tree);
}

TEST(CliBuild, BoxesObjWireframe) {
  const std::string obj = temp("boxes.obj");
  const CliRun r = run("build " + mesh("elephant.off") + " --fitter aabb --split median --boxes-obj " + obj +
                    " --level 3 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["boxes_obj"]["boxes"], 8);  // median: level 3 is full
  EXPECT_EQ(count_lines(obj, "v "), 8u * 8u);
  EXPECT_EQ(count_lines(obj, "l "), 8u * 12u);
  std::filesystem::remove(obj);

  const CliRun deep = run("build " + mesh("elephant.off") + " --fitter aabb --boxes-obj " + obj + " --level 99");
  EXPECT_NE(deep.status, 0);
  EXPECT_NE(deep.err.find("deeper than the tree"), std::string::npos) << deep.err;
}

TEST(CliBuild, BadInputOneLineNonZeroExit) {
  for (const std::string& args : std::vector<std::string>{"build /nonexistent/mesh.off", "build " + mesh("knot1.off") + " --fitter fastest",
        "build " + mesh("knot1.off") + " --split middle", "build " + mesh("knot1.off") + " --leaf-size 0",
        "build " + mesh("knot1.off") + " --grid 3 --epsilon 0.1", "inspect /nonexistent.tree",
        "inspect " + mesh("knot1.off")}) {
    const CliRun r = run(args);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_FALSE(r.err.empty()) << args;
    EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << args << ": " << r.err;
  }
  const CliRun magic = run("inspect " + mesh("knot1.off"));
  EXPECT_NE(magic.err.find("wrong magic"), std::string::npos) << magic.err;
}

}  // namespace
}  // namespace tightbvh
