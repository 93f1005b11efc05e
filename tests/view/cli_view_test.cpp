// `tightbvh view` and `tightbvh collide --view`, run as a user would (the real binary).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "../cli_runner.hpp"

namespace tightbvh {
namespace {

using test::CliRun;

std::string mesh(const char* name) { return std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/" + name; }
std::filesystem::path temp(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("tightbvh_cli_view_test_" + std::to_string(::getpid()) + "_" + name);
}
std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
// The scene JSON inlined into a page.
nlohmann::json scene_of(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"scene\">";
  const std::size_t begin = page.find(open) + open.size();
  return nlohmann::json::parse(page.substr(begin, page.find("</script>", begin) - begin));
}

TEST(CliView, PageWithTwoFittersByDefault) {
  const auto dir = temp("trees");
  const CliRun r = test::run_cli("view " + mesh("knot1.off") + " --level 2 -o " + dir.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("index.html"), std::string::npos) << r.out;
  const nlohmann::json scene = scene_of(slurp(dir / "index.html"));
  EXPECT_EQ(scene["kind"], "trees");
  EXPECT_EQ(scene["level"], 2);
  ASSERT_EQ(scene["trees"].size(), 2u);
  EXPECT_EQ(scene["trees"][0]["fitter"], "pca");
  EXPECT_EQ(scene["trees"][1]["fitter"], "auto");
  EXPECT_EQ(scene["trees"][0]["levels"][2].size(), 4u * 15u);
  std::filesystem::remove_all(dir);
}

TEST(CliView, ChosenFittersInOrder) {
  const auto dir = temp("three");
  const CliRun r =
      test::run_cli("view --fitter aabb --fitter pca --fitter diameter " + mesh("knot1.off") + " -o " + dir.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json scene = scene_of(slurp(dir / "index.html"));
  ASSERT_EQ(scene["trees"].size(), 3u);
  EXPECT_EQ(scene["trees"][2]["fitter"], "diameter");
  std::filesystem::remove_all(dir);
}

TEST(CliView, CollideViewHighlightsContacts) {
  const auto dir = temp("contacts");
  const CliRun r =
      test::run_cli("collide " + mesh("knot1.off") + " " + mesh("elephant.off") +
                    " --pose \"0 -1 0 1 0 0 0 0 1 0.1 0 0\" --fitter pca --all-pairs --json --view " + dir.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  EXPECT_EQ(out["view"], (dir / "index.html").string());
  const nlohmann::json scene = scene_of(slurp(dir / "index.html"));
  EXPECT_EQ(scene["kind"], "contacts");
  EXPECT_EQ(scene["result"]["pairs"], out["pair_count"]);
  EXPECT_GT(scene["contacts"][0].size(), 0u);
  EXPECT_EQ(scene["contacts"][0].size() % 9, 0u);
  std::filesystem::remove_all(dir);
}

TEST(CliView, DistanceViewMarksTheClosestTrianglesAndPoints) {
  const auto dir = temp("distance");
  const CliRun r = test::run_cli("distance " + mesh("knot1.off") + " " + mesh("elephant.off") +
                                 " --pose \"0 -1 0 1 0 0 0 0 1 1.3 0 0\" --json --view " + dir.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  EXPECT_EQ(out["view"], (dir / "index.html").string());
  ASSERT_GT(out["distance"].get<double>(), 0.0);
  const nlohmann::json scene = scene_of(slurp(dir / "index.html"));
  EXPECT_EQ(scene["kind"], "distance");
  EXPECT_EQ(scene["result"]["distance"], out["distance"]);
  EXPECT_EQ(scene["result"]["node_pairs"], out["node_pairs"]);
  EXPECT_EQ(scene["contacts"][0].size(), 9u);  // one closest triangle each
  EXPECT_EQ(scene["contacts"][1].size(), 9u);
  // The segment: the two closest points the query reported, at full precision.
  ASSERT_EQ(scene["closest"].size(), 6u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(scene["closest"][k], out["point_a"][k]);
    EXPECT_EQ(scene["closest"][3 + k], out["point_b"][k]);
  }
  // Beyond the upper bound: no triangles, no segment.
  const CliRun far = test::run_cli("distance " + mesh("knot1.off") + " " + mesh("elephant.off") +
                                   " --pose \"0 -1 0 1 0 0 0 0 1 1.3 0 0\" --upper-bound 1e-6 --view " + dir.string());
  ASSERT_EQ(far.status, 0) << far.err;
  const nlohmann::json none = scene_of(slurp(dir / "index.html"));
  EXPECT_TRUE(none["result"]["beyond_upper_bound"].get<bool>());
  EXPECT_EQ(none["closest"].size(), 0u);
  EXPECT_EQ(none["contacts"][0].size(), 0u);
  std::filesystem::remove_all(dir);
}

TEST(CliView, CollideViewDrawsTheFirstHitDescent) {
  const auto dir = temp("descent");
  const CliRun r = test::run_cli("collide " + mesh("knot1.off") + " " + mesh("elephant.off") +
                                 " --pose \"0 -1 0 1 0 0 0 0 1 0.1 0 0\" --json --view " + dir.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  ASSERT_TRUE(out["hit"].get<bool>());
  const nlohmann::json scene = scene_of(slurp(dir / "index.html"));
  const nlohmann::json& d = scene["descent"];
  // The recorded descent is the query's: one visited pair per box test, all counted per level.
  EXPECT_EQ(d["visited"], out["box_tests"]);
  std::uint64_t counted = 0, hits = 0;
  for (const auto& level : d["per_level"]) {
    for (const auto& n : level) counted += n.get<std::uint64_t>();
    hits += level[3].get<std::uint64_t>();
  }
  EXPECT_EQ(counted, out["box_tests"].get<std::uint64_t>());
  EXPECT_EQ(hits, 1u);  // first_hit stops at its one leaf pair with a contact
  const std::size_t drawn = d["drawn"];
  EXPECT_EQ(drawn, std::min<std::uint64_t>(out["box_tests"].get<std::uint64_t>(), d["max_drawn"].get<std::uint64_t>()));
  ASSERT_EQ(d["steps"].size(), 4 * drawn);
  EXPECT_EQ(d["steps"][2], 1);  // the root pair overlaps and is descended
  std::filesystem::remove_all(dir);
}

TEST(CliView, BadInputIsOneLineAndNonZeroExit) {
  const auto dir = temp("bad");
  const auto blocker = temp("blocker");
  std::ofstream(blocker) << "a file, not a directory";
  for (const std::string& args : {"view " + mesh("knot1.off") + " --fitter nope -o " + dir.string(),
                                  "view " + mesh("knot1.off") + " --level 999 -o " + dir.string(),
                                  "view " + dir.string() + "/missing.off -o " + dir.string(),
                                  "view " + mesh("knot1.off") + " --fitter aabb -o " + (blocker / "sub").string(),
                                  "collide " + mesh("knot1.off") + " " + mesh("knot1.off") + " --fitter aabb --view " +
                                      (blocker / "sub").string(),
                                  "distance " + mesh("knot1.off") + " " + mesh("knot1.off") + " --fitter aabb --view " +
                                      (blocker / "sub").string()}) {
    SCOPED_TRACE(args);
    const CliRun r = test::run_cli(args);
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;  // one line
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "index.html"));
  std::filesystem::remove(blocker);
}

}  // namespace
}  // namespace tightbvh
