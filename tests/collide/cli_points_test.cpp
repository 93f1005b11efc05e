// `tightbvh points`, run as a user would: text and .npy input, text and JSON output, --signed,
// --max-distance, -o, and errors naming the file, line or argument.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../cli_runner.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"

namespace tightbvh {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

const std::string kMesh = std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/fandisk.off";
const std::vector<Vec3> kPoints = {{0, 0, 0}, {0, 0, 0.2}, {1, 0.5, 0.25}, {0.1696, 0.04095, -0.0471}};

class CliPoints : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::cli_path())) GTEST_SKIP() << test::cli_path() << " not built";
    dir_ = fs::path(::testing::TempDir()) /
           ("tightbvh_cli_points_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A .npy file: version 1, the given descr and shape text, then `data` as is.
  std::string npy(const std::string& name, const std::string& descr, const std::string& shape, const std::string& data,
                  const std::string& order = "False") {
    std::string header = "{'descr': '" + descr + "', 'fortran_order': " + order + ", 'shape': " + shape + ", }";
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::ofstream out(dir_ / name, std::ios::binary);
    out << "\x93NUMPY" << char(1) << char(0) << char(header.size() & 0xff) << char(header.size() >> 8) << header
        << data;
    return (dir_ / name).string();
  }
  std::string text(const std::string& name, const std::string& content) {
    std::ofstream(dir_ / name) << content;
    return (dir_ / name).string();
  }

  fs::path dir_;
};

template <class T>
std::string raw(const std::vector<T>& values) {
  return {reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)};
}

TEST_F(CliPoints, TextAndNpyGiveTheLibrarysAnswer) {
  const Model model(load_mesh(kMesh));
  const std::vector<ClosestPoint> want = signed_distance(model, Pose::identity(), kPoints);
  std::vector<double> rows, columns;
  for (const Vec3& p : kPoints) rows.insert(rows.end(), {p.x(), p.y(), p.z()});
  for (int k = 0; k < 3; ++k)
    for (const Vec3& p : kPoints) columns.push_back(p[k]);
  const std::string inputs[] = {
      text("p.txt", "# probes\n0 0 0\n\n0 0 0.2\n1 0.5 0.25\n  0.1696 0.04095 -0.0471\n"),
      npy("p.npy", "<f8", "(4, 3)", raw(rows)),
      npy("f.npy", "<f8", "(4, 3)", raw(columns), "True"),
  };
  for (const std::string& input : inputs) {
    SCOPED_TRACE(input);
    const CliRun r = test::run_cli("points " + test::shell_quote(kMesh) + " " + test::shell_quote(input) + " --signed --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["count"].get<std::size_t>(), kPoints.size());
    for (std::size_t i = 0; i < kPoints.size(); ++i) {
      const auto& item = j["results"][i];
      EXPECT_EQ(item["distance"].get<double>(), want[i].distance);
      EXPECT_EQ(item["triangle"].get<std::uint32_t>(), want[i].triangle);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(item["point"][k].get<double>(), want[i].point[k]);
    }
    EXPECT_LT(j["results"][0]["distance"].get<double>(), 0.0);  // inside
    EXPECT_EQ(j["results"][3]["distance"].get<double>(), 0.0);  // a vertex
  }
  // float32 .npy: the points rounded to float.
  std::vector<float> floats;
  for (const double x : rows) floats.push_back(static_cast<float>(x));
  const CliRun f = test::run_cli("points " + test::shell_quote(kMesh) + " " + npy("p32.npy", "<f4", "(4, 3)", raw(floats)) + " --json");
  ASSERT_EQ(f.status, 0) << f.err;
  EXPECT_EQ(nlohmann::json::parse(f.out)["results"].size(), 4u);
}

TEST_F(CliPoints, TextOutputMaxDistanceAndOutputFile) {
  const std::string input = text("p.txt", "0 0 0\n1 0.5 0.25\n");
  const CliRun r = test::run_cli("points " + test::shell_quote(kMesh) + " " + input + " --max-distance 0.1 -o " +
                                 test::shell_quote((dir_ / "out.txt").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  std::ifstream in(dir_ / "out.txt");
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  std::istringstream fields(first);
  double d, x, y, z;
  std::uint32_t t;
  ASSERT_TRUE(fields >> d >> x >> y >> z >> t) << first;
  EXPECT_GT(d, 0.0);
  EXPECT_LT(d, 0.1);
  EXPECT_EQ(second, ">= 0.10000000000000001 beyond");
}

TEST_F(CliPoints, ErrorsNameTheFileLineOrArgument) {
  const std::string two = text("ok.txt", "0 0 0\n");
  const std::string open = std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/corpus/cgal/cube-ouvert.off";
  const std::vector<std::pair<std::string, std::string>> cases{
      {kMesh + " " + text("bad.txt", "0 0 0\n1 2\n"), "bad.txt:2: expected three numbers"},
      {kMesh + " " + text("four.txt", "0 0 0 4\n"), "four.txt:1"},
      {kMesh + " " + text("nan.txt", "0 0 0\n0 nan 0\n"), "nan.txt:2"},
      {kMesh + " " + npy("i.npy", "<i8", "(1, 3)", std::string(24, '\0')), "dtype '<i8'"},
      {kMesh + " " + npy("s.npy", "<f8", "(3,)", std::string(24, '\0')), "shape (3,)"},
      {kMesh + " " + npy("short.npy", "<f8", "(2, 3)", std::string(24, '\0')), "24 data bytes"},
      {kMesh + " " + text("x.npy", "0 0 0\n"), "no .npy magic"},
      {kMesh + " " + (dir_ / "missing.txt").string(), "missing.txt"},
      {open + " " + two + " --signed", "not closed"},
      {kMesh + " " + two + " --max-distance -1", "--max-distance"},
  };
  for (const auto& [args, fragment] : cases) {
    const CliRun r = test::run_cli("points " + args);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << args << ": '" << fragment << "' not in: " << r.err;
  }
}

}  // namespace
}  // namespace tightbvh
