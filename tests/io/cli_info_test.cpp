// `tightbvh info` as a user runs it: exit status, stdout, stderr.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "../cli_runner.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path cli = tightbvh::test::cli_path();
const fs::path meshes = fs::path(TIGHTBVH_SOURCE_DIR) / "meshes";

using Outcome = tightbvh::test::CliRun;

const auto quote = tightbvh::test::shell_quote;

class CliInfo : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(cli)) GTEST_SKIP() << cli << " not built (TIGHTBVH_BUILD_APPS=OFF?)";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / (std::string("tightbvh_cli_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static Outcome run(const std::string& args) { return tightbvh::test::run_cli(args); }

  static void expect_one_line_error(const Outcome& r, const std::string& fragment) {
    EXPECT_NE(r.status, 0);
    EXPECT_TRUE(r.out.empty()) << r.out;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not exactly one line: " << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  }

  fs::path dir_;
};

// The header counts of an OFF file, read independently of the loader.
std::pair<std::size_t, std::size_t> off_header(const fs::path& path) {
  std::ifstream in(path);
  std::string magic;
  std::size_t v = 0, f = 0;
  in >> magic >> v >> f;
  return {v, f};
}

TEST_F(CliInfo, JsonOnShippedMeshes) {
  const fs::path knot = meshes / "knot1.off";
  const fs::path elephant = meshes / "elephant.off";
  const Outcome r = run("info --json " + quote(knot.string()) + " " + quote(elephant.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // nothing leaks from assimp
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const fs::path path = i == 0 ? knot : elephant;
    const auto [v, f] = off_header(path);
    EXPECT_EQ(j[i]["mesh"], path.string());
    EXPECT_EQ(j[i]["vertices"], v);
    EXPECT_EQ(j[i]["triangles"], f);  // both files hold triangles only
    EXPECT_EQ(j[i]["degenerate_triangles"], 0);
    for (int a = 0; a < 3; ++a) EXPECT_LT(j[i]["bounds"]["min"][a].get<double>(), j[i]["bounds"]["max"][a].get<double>());
  }
}

TEST_F(CliInfo, TextOnShippedMesh) {
  const Outcome r = run("info " + quote((meshes / "knot1.off").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("3200 vertices, 6400 triangles, 0 degenerate"), std::string::npos) << r.out;
}

TEST_F(CliInfo, MissingFileIsOneLineAndNonZero) {
  const fs::path missing = dir_ / "missing.off";
  expect_one_line_error(run("info " + quote(missing.string())), missing.string() + ": no such file");
}

TEST_F(CliInfo, InvalidFileIsOneLineAndNonZero) {
  const fs::path bad = dir_ / "bad.off";
  std::ofstream(bad) << "OFF\n4 4 0\n0 0 0\n1 0 0\n";
  expect_one_line_error(run("info --json " + quote(bad.string())), "truncated OFF");
}

// assimp logs through its DefaultLogger, which we never create: nothing of it may reach the user.
TEST_F(CliInfo, BrokenCorpusFilesGiveOneLineEach) {
  const fs::path invalid = meshes / "corpus" / "assimp" / "invalid";
  if (!fs::is_directory(invalid)) GTEST_SKIP() << "corpus not fetched: run meshes/fetch-corpus";
  for (const auto& entry : fs::directory_iterator(invalid)) {
    SCOPED_TRACE(entry.path().string());
    expect_one_line_error(run("info " + quote(entry.path().string())), entry.path().string() + ": ");
  }
}

TEST_F(CliInfo, ParseErrorsAreOneLineAndNonZero) {
  expect_one_line_error(run("info"), "required");
  expect_one_line_error(run("info --bogus " + quote((meshes / "knot1.off").string())), "--bogus");
  expect_one_line_error(run(""), "subcommand");
}

TEST_F(CliInfo, HelpExitsZero) {
  const Outcome r = run("info --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--json"), std::string::npos);
}

}  // namespace
