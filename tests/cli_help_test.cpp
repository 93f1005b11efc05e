// Every `tightbvh` subcommand's --help ends with one example, and the example runs as printed
// (from a folder where meshes/ and examples/ are the shipped ones, so that its output files land in a
// temporary folder); bad input names the file, line or argument at fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace tightbvh {
namespace {

namespace fs = std::filesystem;
using test::CliRun;

const fs::path kSource = TIGHTBVH_SOURCE_DIR;

class CliHelp : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::cli_path())) GTEST_SKIP() << test::cli_path() << " not built (TIGHTBVH_BUILD_APPS=OFF?)";
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / (std::string("tightbvh_cli_help_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::create_directory_symlink(kSource / "meshes", dir_ / "meshes");
    fs::create_directory_symlink(kSource / "examples", dir_ / "examples");  // the scene files
    previous_ = fs::current_path();
    fs::current_path(dir_);
  }
  void TearDown() override {
    if (dir_.empty()) return;
    fs::current_path(previous_);
    fs::remove_all(dir_);
  }

  fs::path dir_, previous_;
};

// The example of `--help`: the line after the one starting with "Example", without "tightbvh ".
std::string example_of(const std::string& help) {
  const std::size_t label = help.find("\nExample");
  if (label == std::string::npos) return "";
  const std::size_t start = help.find('\n', label + 1) + 1;
  const std::string line = help.substr(start, help.find('\n', start) - start);
  const std::string prefix = "  tightbvh ";
  return line.rfind(prefix, 0) == 0 ? line.substr(prefix.size()) : "";
}

// The subcommands `tightbvh --help` lists (the lines below "Subcommands:"), in its order.
std::vector<std::string> listed_subcommands() {
  const std::string help = test::run_cli("--help").out;
  std::vector<std::string> names;
  std::size_t line = help.find("\nSubcommands:\n");
  if (line == std::string::npos) return names;
  line = help.find('\n', line + 1) + 1;
  while (line < help.size() && help.compare(line, 2, "  ") == 0) {
    const std::size_t end = help.find(' ', line + 2);
    names.push_back(help.substr(line + 2, end - line - 2));
    line = help.find('\n', line) + 1;
  }
  return names;
}

TEST_F(CliHelp, EverySubcommandShowsAnExampleThatRuns) {
  // In this order: inspect reads the tree that build's example writes.
  const std::vector<std::string> commands{"info", "fit", "build", "inspect", "collide", "distance", "view", "scene", "points"};
  ASSERT_EQ(commands, listed_subcommands()) << "a subcommand was added: give it an example and list it here";
  for (const std::string& command : commands) {
    SCOPED_TRACE(command);
    const CliRun help = test::run_cli(command + " --help");
    ASSERT_EQ(help.status, 0) << help.err;
    const std::string example = example_of(help.out);
    ASSERT_EQ(example.rfind(command + " ", 0), 0u) << "no example of `" << command << "` in:\n" << help.out;
    const CliRun run = test::run_cli(example);
    EXPECT_EQ(run.status, 0) << "tightbvh " << example << ": " << run.err;
    EXPECT_EQ(run.err, "") << example;
    EXPECT_FALSE(run.out.empty()) << example;
  }
  EXPECT_TRUE(fs::exists(dir_ / "elephant.tree"));
  EXPECT_TRUE(fs::exists(dir_ / "knot1-view" / "index.html"));
}

// One line on stderr, a non-zero exit, and the argument, file or line at fault named in it.
TEST_F(CliHelp, ErrorsNameTheArgumentFileOrLine) {
  {
    std::ofstream bad("bad.off");
    bad << "OFF\n3 1 0\n0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n";
  }
  const std::string two = "meshes/knot1.off meshes/elephant.off ";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"collide " + two + "--pose \"1 0 0\"", "--pose"},
      {"collide " + two + "--fitter nope", "--fitter"},
      {"collide " + two + "--margin -0.1", "--margin"},
      {"distance " + two + "--rel-error -1", "--rel-error"},
      {"distance " + two + "--abs-error nan", "--abs-error"},
      {"distance " + two + "--upper-bound -2", "--upper-bound"},
      {"distance " + two + "--fitter nope", "--fitter"},
      {"build meshes/knot1.off --fitter nope", "--fitter"},
      {"build meshes/knot1.off --split nope", "--split"},
      {"build meshes/knot1.off --leaf-size 0", "--leaf-size: must be a positive number, got '0'"},
      {"collide " + two + "--leaf-size 0", "--leaf-size"},
      {"build meshes/knot1.off --boxes-obj b.obj --level 99", "--level"},
      {"build meshes/knot1.off -o no/such/folder/knot1.tree", "no/such/folder/knot1.tree"},
      {"fit meshes/knot1.off --method nope", "--method"},
      {"view meshes/knot1.off --fitter nope", "--fitter"},
      {"info meshes/nonexistent.off", "meshes/nonexistent.off"},
      {"info bad.off", "bad.off"},
      {"info bad.off", "line 4"},
      {"inspect nonexistent.tree", "nonexistent.tree"},
      {"inspect meshes/knot1.off", "meshes/knot1.off"},
      {"collide meshes/knot1.off meshes/nonexistent.off", "meshes/nonexistent.off"},
  };
  for (const auto& [args, fragment] : cases) {
    const CliRun r = test::run_cli(args);
    EXPECT_NE(r.status, 0) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << args << ": '" << fragment << "' not in: " << r.err;
    EXPECT_LT(r.err.size(), 300u) << args << ": " << r.err;  // e.g. no limit printed in full
  }
}

}  // namespace
}  // namespace tightbvh
