// `tightbvh scene`, run as a user would: text and JSON, frames, errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>

#include "../cli_runner.hpp"
#include "tightbvh/scene_file.hpp"

namespace tightbvh {
namespace {

namespace fs = std::filesystem;

struct SceneFolder {
  fs::path dir = fs::temp_directory_path() / ("tightbvh_cli_scene_" + std::to_string(::getpid()));
  SceneFolder() {
    fs::create_directories(dir);
    // Three boxes: a and b overlap, c is 0.5 from b; the frame moves c onto b and a away.
    std::ofstream(dir / "box.off") << "OFF\n8 12 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
                                      "3 0 2 1\n3 1 2 3\n3 4 5 6\n3 5 7 6\n3 0 1 4\n3 1 5 4\n3 2 6 3\n3 3 6 7\n"
                                      "3 0 4 2\n3 2 4 6\n3 1 3 5\n3 3 7 5\n";
    std::ofstream(dir / "scene.json") << R"({"models": {"box": "box.off"}, "objects": [
      {"name": "a", "model": "box", "pose": [1,0,0, 0,1,0, 0,0,1, 0,0,0]},
      {"name": "b", "model": "box", "pose": [1,0,0, 0,1,0, 0,0,1, 0.5,0,0]},
      {"name": "c", "model": "box", "pose": [1,0,0, 0,1,0, 0,0,1, 2,0,0]}], "frames": "moves.txt"})";
    std::ofstream(dir / "moves.txt") << "c 1 0 0 0 1 0 0 0 1 1.2 0 0\na 1 0 0 0 1 0 0 0 1 0 5 0\n";
  }
  ~SceneFolder() { fs::remove_all(dir); }
  [[nodiscard]] std::string scene() const { return test::shell_quote((dir / "scene.json").string()); }
};

TEST(CliScene, JsonPairsPerFrame) {
  const SceneFolder f;
  const test::CliRun run = test::run_cli("scene " + f.scene() + " --json --distance 0.6");
  ASSERT_EQ(run.status, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["pairs"], nlohmann::json::parse(R"([["a", "b"]])"));
  EXPECT_EQ(j["closer"], nlohmann::json::parse(R"([["a", "b"], ["b", "c"]])"));
  ASSERT_EQ(j["frames"].size(), 1u);
  EXPECT_EQ(j["frames"][0]["pairs"], nlohmann::json::parse(R"([["b", "c"]])"));
  EXPECT_EQ(j["frames"][0]["closer"], nlohmann::json::parse(R"([["b", "c"]])"));
}

TEST(CliScene, TextAndErrors) {
  const SceneFolder f;
  const test::CliRun run = test::run_cli("scene " + f.scene() + " --all-pairs");
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("scene: 1 touching object pairs\n  a b  ("), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("frame 0: 1 touching object pairs\n  b c"), std::string::npos) << run.out;

  std::ofstream(f.dir / "moves.txt") << "c 1 0 0 0 1 0 0 0 1 1.2 0 0\n---\nq 1 0 0 0 1 0 0 0 1 0 0 0\n";
  const test::CliRun bad = test::run_cli("scene " + f.scene());
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("moves.txt:3: unknown object 'q'"), std::string::npos) << bad.err;
}

TEST(CliScene, ShapesInTheShippedArmScene) {
  // examples/scenes/capsule-arm.json: a mesh part, a box table, capsule links, a sphere gripper.
  // The CLI's pairs are the library's on the same file (the allowed pairs left out).
  const std::string path = std::string(TIGHTBVH_SOURCE_DIR) + "/examples/scenes/capsule-arm.json";
  const test::CliRun run = test::run_cli("scene " + test::shell_quote(path) + " --json --distance 0.3");
  ASSERT_EQ(run.status, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const SceneFile file = load_scene_file(path);
  nlohmann::json want = nlohmann::json::array();
  for (const ObjectPairHit& hit : collide(file.scene))
    want.push_back({file.scene.object(hit.a).name, file.scene.object(hit.b).name});
  EXPECT_EQ(j["pairs"], want);
  // The gripper holds the part; the upper arm stands on the table, exactly tangent.
  EXPECT_EQ(j["pairs"], nlohmann::json::parse(R"([["part", "gripper"], ["table", "upper-arm"]])"));
  EXPECT_EQ(j["closer"].size(), 3u);  // and the forearm passes 0.17 above the part
}

}  // namespace
}  // namespace tightbvh
