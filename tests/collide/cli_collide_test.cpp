// `tightbvh collide`, run as a user would (popen of the real binary).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>

#include "../cli_runner.hpp"
namespace tightbvh {
namespace {

using test::CliRun;

CliRun run(const std::string& args) { return test::run_cli("collide " + args); }

std::string meshes() {
  const std::string dir = std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/";
  return dir + "knot1.off " + dir + "elephant.off";
}

TEST(CliCollide, JsonFirstHitAndAllPairs) {
  const std::string pose = " --pose \"0 -1 0 1 0 0 0 0 1 0.1 0 0\" --fitter pca --json";
  const CliRun all = run(meshes() + pose + " --all-pairs");
  ASSERT_EQ(all.status, 0) << all.err;
  const auto j = nlohmann::json::parse(all.out);
  EXPECT_TRUE(j["hit"].get<bool>());
  EXPECT_EQ(j["mode"], "all_pairs");
  EXPECT_GT(j["pair_count"].get<int>(), 0);
  EXPECT_EQ(j["pairs"].size(), j["pair_count"].get<std::size_t>());
  EXPECT_GT(j["box_tests"].get<int>(), 0);
  EXPECT_GE(j["seconds"].get<double>(), 0.0);
  const CliRun first = run(meshes() + pose);
  ASSERT_EQ(first.status, 0) << first.err;
  const auto f = nlohmann::json::parse(first.out);
  EXPECT_TRUE(f["hit"].get<bool>());
  EXPECT_EQ(f["pair_count"], 1);
  EXPECT_LE(f["box_tests"].get<int>(), j["box_tests"].get<int>());
}

TEST(CliCollide, ContactsJsonAndErrors) {
  const std::string pose = " --pose \"0 -1 0 1 0 0 0 0 1 0.1 0 0\" --fitter pca";
  const CliRun r = run(meshes() + pose + " --all-pairs --contacts --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["contacts"].size(), j["pair_count"].get<std::size_t>());
  double length = 0.0;
  for (const auto& c : j["contacts"]) {
    const auto& p = c["points"];
    if (c["kind"] != "segment") continue;
    ASSERT_EQ(p.size(), 2u);
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = p[1][k].get<double>() - p[0][k].get<double>();
      d2 += d * d;
    }
    length += std::sqrt(d2);
  }
  EXPECT_GT(j["curve_length"].get<double>(), 0.0);
  EXPECT_NEAR(j["curve_length"].get<double>(), length, 1e-9 * length);
  const CliRun text = run(meshes() + pose + " --all-pairs --contacts");
  EXPECT_NE(text.out.find("intersection curve: "), std::string::npos) << text.out;
  const CliRun first = run(meshes() + pose + " --contacts");  // contacts need --all-pairs
  EXPECT_NE(first.status, 0);
  EXPECT_NE(first.err.find("contacts"), std::string::npos) << first.err;
}

TEST(CliCollide, TextSeparated) {
  const CliRun r = run(meshes() + " --pose \"1 0 0 0 1 0 0 0 1 5 0 0\" --fitter aabb");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("hit: no"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("box tests: "), std::string::npos) << r.out;
}

TEST(CliCollide, BadInputIsOneLineAndNonZeroExit) {
  for (const char* pose : {"1 0 0 0 1 0 0 0 1 0 0",        // 11 numbers
                           "1 0 0 0 1 0 0 0 1 0 0 0 0",    // 13 numbers
                           "1 0 0 0 1 0 0 0 2 0 0 0",      // not orthonormal
                           "1 0 0 0 1 0 0 0 -1 0 0 0",     // reflection
                           "1 0 0 0 1 0 0 0 1 nan 0 0",    // NaN
                           "1 0 0 0 1 0 0 0 1 inf 0 0",    // Inf
                           "1 0 0 0 1 0 0 0 1 0x 0 0"}) {  // not a number
    const CliRun r = run(meshes() + " --fitter pca --pose \"" + pose + "\"");
    EXPECT_NE(r.status, 0) << pose;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << pose << ": " << r.err;
    EXPECT_NE(r.err.find("--pose"), std::string::npos) << r.err;
  }
  const CliRun fitter = run(meshes() + " --fitter nope");
  EXPECT_NE(fitter.status, 0);
  const CliRun missing = run(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/knot1.off /nonexistent.off --fitter pca");
  EXPECT_NE(missing.status, 0);
}

}  // namespace
}  // namespace tightbvh
