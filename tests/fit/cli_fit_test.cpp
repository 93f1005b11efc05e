// `tightbvh fit`, run as a user would: JSON fields, boxes that contain the mesh, one-line errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "../cli_runner.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/obb.hpp"

namespace tightbvh {
namespace {

const std::string kElephant = std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/elephant.off";

Vec3 vec(const nlohmann::json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

void expect_one_line_error(const test::CliRun& r, const std::string& fragment) {
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(r.out.empty()) << r.out;
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not exactly one line: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
}

TEST(CliFit, JsonBoxesContainTheMeshAndAreOrderedByTightness) {
  const Mesh mesh = load_mesh(kElephant);
  double volume[4] = {};
  const char* methods[4] = {"aabb", "pca", "approx", "exact"};
  for (int i = 0; i < 4; ++i) {
    const auto run = test::run_cli("fit " + test::shell_quote(kElephant) + " --method " + methods[i] + " --json");
    ASSERT_EQ(run.status, 0) << run.err;
    const auto json = nlohmann::json::parse(run.out);
    ASSERT_EQ(json.size(), 1u);
    const auto& j = json[0];
    EXPECT_EQ(j.at("method"), methods[i]);
    for (const char* key : {"volume", "center", "axes", "half_extents", "hull_vertices", "seconds"})
      EXPECT_TRUE(j.contains(key)) << key;
    Obb box;
    box.center = vec(j.at("center"));
    for (int a = 0; a < 3; ++a) box.axes.col(a) = vec(j.at("axes").at(a));
    box.half_extents = vec(j.at("half_extents"));
    EXPECT_LT((box.axes.transpose() * box.axes - Mat3::Identity()).norm(), 1e-9);
    EXPECT_NEAR(box.axes.determinant(), 1.0, 1e-9);
    EXPECT_NEAR(box.volume(), j.at("volume").get<double>(), 1e-12 * box.volume());
    // JSON doubles round-trip exactly, so containment is checked on the printed box itself.
    for (const Vec3& v : mesh.vertices) ASSERT_TRUE(box.contains(v, containment_tolerance(box))) << methods[i];
    volume[i] = box.volume();
  }
  EXPECT_LE(volume[3], volume[2] * (1 + 1e-9));  // exact <= approx
  EXPECT_LE(volume[2], volume[1]);               // approx <= pca (elephant: 0.2946 vs 0.3589)
  EXPECT_LE(volume[3], volume[0]);               // exact <= aabb
}

TEST(CliFit, AllPrintsEveryMethodAsText) {
  const auto r = test::run_cli("fit " + test::shell_quote(kElephant) + " --method all");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* m : {"aabb", "pca", "pca-vertex", "diameter", "approx", "approx-snap", "exact", "eberly2015"})
    EXPECT_NE(r.out.find(std::string("\n") + m + " "), std::string::npos) << m << " missing in\n" << r.out;
}

TEST(CliFit, BadInputIsAOneLineError) {
  expect_one_line_error(test::run_cli("fit /nonexistent/mesh.off"), "no such file");
  expect_one_line_error(test::run_cli("fit " + test::shell_quote(kElephant) + " --method bogus"), "bogus");
  expect_one_line_error(test::run_cli("fit " + test::shell_quote(kElephant) + " --method approx --epsilon -1"),
                        "--epsilon must be a positive finite number");
  expect_one_line_error(test::run_cli("fit " + test::shell_quote(kElephant) + " --method approx --epsilon nan"),
                        "--epsilon");
  expect_one_line_error(test::run_cli("fit " + test::shell_quote(kElephant) + " --grid 0"), "--grid");
  expect_one_line_error(test::run_cli("fit " + test::shell_quote(kElephant) + " --grid 2 --epsilon 0.1"),
                        "excludes");
}

}  // namespace
}  // namespace tightbvh
