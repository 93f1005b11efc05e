// `tightbvh fit`, run as a user would: JSON fields, boxes that contain the mesh, one-line errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <cmath>
#include <set>
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

// Sunday's containers from the CLI: the printed parameters contain every vertex; "all" adds
// each volume relative to the exact box (1 for exact itself, >= 1 for every other box).
TEST(CliFit, ContainersContainTheMeshAndAllComparesWithTheExactBox) {
  const Mesh mesh = load_mesh(kElephant);
  const auto fit_json = [](const std::string& method) {
    const auto run = test::run_cli("fit " + test::shell_quote(kElephant) + " --method " + method + " --json");
    EXPECT_EQ(run.status, 0) << run.err;
    const auto json = nlohmann::json::parse(run.out);
    EXPECT_EQ(json.size(), 1u);
    EXPECT_EQ(json[0].at("method"), method);
    return json[0];
  };
  for (const char* name : {"ball", "fast-ball"}) {
    const auto j = fit_json(name);
    const Vec3 center = vec(j.at("center"));
    const double radius = j.at("radius").get<double>();
    EXPECT_NEAR(j.at("volume").get<double>(), 4.0 / 3.0 * M_PI * radius * radius * radius, 1e-12);
    for (const Vec3& v : mesh.vertices) ASSERT_LE((v - center).norm(), radius * (1 + 1e-12)) << name;
  }
  {
    const auto j = fit_json("ellipsoid");
    const Vec3 center = vec(j.at("center")), radii = vec(j.at("radii"));
    Mat3 axes;
    for (int a = 0; a < 3; ++a) axes.col(a) = vec(j.at("axes").at(a));
    for (const Vec3& v : mesh.vertices)
      ASSERT_LE((axes.transpose() * (v - center)).cwiseQuotient(radii).squaredNorm(), 1 + 1e-9);
  }
  for (const char* name : {"diamond", "dop14", "dop18", "dop26"}) {
    const auto j = fit_json(name);
    for (const auto& slab : j.at("slabs")) {
      const Vec3 d = vec(slab.at("direction"));
      const double lo = slab.at("min").get<double>(), hi = slab.at("max").get<double>();
      for (const Vec3& v : mesh.vertices) {
        ASSERT_GE(d.dot(v), lo - 1e-12) << name;
        ASSERT_LE(d.dot(v), hi + 1e-12) << name;
      }
    }
  }
  const auto run = test::run_cli("fit " + test::shell_quote(kElephant) + " --method all --json");
  ASSERT_EQ(run.status, 0) << run.err;
  const auto all = nlohmann::json::parse(run.out);
  std::set<std::string> methods;
  for (const auto& j : all) {
    const std::string method = j.at("method");
    methods.insert(method);
    const double relative = j.at("volume_vs_exact").get<double>();
    if (method == "exact") EXPECT_DOUBLE_EQ(relative, 1.0);
    if (j.contains("half_extents")) EXPECT_GE(relative, 1.0 - 1e-9) << method;  // exact is the smallest box
  }
  for (const char* m : {"exact", "approx", "ball", "fast-ball", "ellipsoid", "diamond", "dop14", "dop26"})
    EXPECT_TRUE(methods.count(m)) << m;
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
