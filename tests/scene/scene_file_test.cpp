// The scene file and its frames file: loading, and errors that name the key or line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include "tightbvh/error.hpp"
#include "tightbvh/scene_file.hpp"

namespace tightbvh {
namespace {

namespace fs = std::filesystem;

// A folder of its own per test process, with the shipped meshes referenced by absolute path.
struct Folder {
  fs::path dir = fs::temp_directory_path() / ("tightbvh_scene_file_" + std::to_string(::getpid()));
  Folder() {
    fs::create_directories(dir);
    write("tet.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
    write("box.off",
          "OFF\n8 12 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
          "3 0 2 1\n3 1 2 3\n3 4 5 6\n3 5 7 6\n3 0 1 4\n3 1 5 4\n3 2 6 3\n3 3 6 7\n3 0 4 2\n3 2 4 6\n"
          "3 1 3 5\n3 3 7 5\n");
  }
  ~Folder() { fs::remove_all(dir); }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return dir / name;
  }
};

// Two small meshes written next to the scene file (paths relative to its folder): a
// tetrahedron and a box, both within [0, 1]^3.
std::string meshes_json() { return R"({"knot": "tet.off", "fan": "box.off"})"; }

std::string scene_json(const std::string& objects, const std::string& extra = "") {
  return R"({"models": )" + meshes_json() + R"(, "objects": [)" + objects + "]" + extra + "}";
}

const std::string kAt0 = R"("pose": [1,0,0, 0,1,0, 0,0,1, 0,0,0])";
const std::string kAt5 = R"("pose": [1,0,0, 0,1,0, 0,0,1, 5,0,0])";

std::string error_of(const fs::path& path) {
  try {
    (void)load_scene_file(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SceneFile, LoadsModelsObjectsAllowedPairsAndFrames) {
  const Folder f;
  f.write("moves.txt",
          "b 1 0 0 0 1 0 0 0 1 0.2 0 0\n---\n\nb 1 0 0 0 1 0 0 0 1 9 0 0\na 0 -1 0 1 0 0 0 0 1 0 0 0\n---\n");
  const fs::path path = f.write(
      "scene.json", scene_json(R"({"name": "a", "model": "knot", )" + kAt0 + R"(}, {"name": "b", "model": "knot", )" +
                                   kAt5 + R"(}, {"name": "c", "model": "fan", )" + kAt0 + "}",
                               R"(, "allowed": [["a", "c"]], "frames": "moves.txt")"));
  const SceneFile s = load_scene_file(path);
  EXPECT_EQ(s.models.size(), 2u);
  EXPECT_EQ(s.scene.size(), 3u);
  EXPECT_EQ(s.scene.model_count(), 2u);  // a and b share the knot
  const ObjectId a = *s.scene.find("a"), b = *s.scene.find("b"), c = *s.scene.find("c");
  EXPECT_TRUE(s.scene.allowed(a, c));
  EXPECT_EQ(s.scene.object(b).pose.translation, Vec3(5, 0, 0));
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].objects, std::vector<ObjectId>{b});
  EXPECT_EQ(s.frames[1].objects, (std::vector<ObjectId>{b, a}));
  EXPECT_EQ(s.frames[1].poses[1].rotation(0, 1), -1.0);
  // a and c touch but are allowed; b moves onto both in the first frame.
  EXPECT_TRUE(collide(s.scene).empty());
  Scene moved = s.scene;
  moved.set_poses(s.frames[0].objects, s.frames[0].poses);
  const auto hits = collide(moved);
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_EQ(std::pair(hits[0].a, hits[0].b), std::pair(a, b));
  EXPECT_EQ(std::pair(hits[1].a, hits[1].b), std::pair(b, c));
}

TEST(SceneFile, ErrorsNameTheKeyOrLine) {
  const Folder f;
  const auto expect_error = [&](const std::string& text, const std::string& needle) {
    const std::string message = error_of(f.write("bad.json", text));
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  };
  expect_error("{", "not valid JSON");
  expect_error(R"({"objects": []})", "missing \"models\"");
  expect_error(scene_json(R"({"name": "a", "model": "cow", )" + kAt0 + "}"), "objects[0].model: unknown model 'cow'");
  expect_error(scene_json(R"({"name": "a", "model": "knot", )" + kAt0 + R"(}, {"name": "a", "model": "knot", )" +
                          kAt5 + "}"),
               "objects[1].name: duplicate name 'a'");
  expect_error(scene_json(R"({"name": "a", "model": "knot", "pose": [1, 0, 0]})"), "objects[0].pose: a pose is 12 numbers");
  expect_error(scene_json(R"({"name": "a", "model": "knot", "pose": [1,0,0, 0,1,0, 0,0,1, 0,"x",0]})"),
               "objects[0].pose[10]: not a number");
  expect_error(scene_json(R"({"name": "a", "model": "knot", "pose": [1,0.01,0, 0,1,0, 0,0,1, 0,0,0]})"),
               "not orthonormal");
  expect_error(scene_json(R"({"name": "a", "model": "knot", )" + kAt0 + "}", R"(, "allowed": [["a", "z"]])"),
               "allowed[0]: unknown object 'z'");
  expect_error(R"({"models": {"m": "nowhere.off"}, "objects": []})", "models.m: ");

  const std::string one = scene_json(R"({"name": "a", "model": "knot", )" + kAt0 + "}", R"(, "frames": "f.txt")");
  const auto expect_frame_error = [&](const std::string& frames, const std::string& needle) {
    f.write("f.txt", frames);
    const std::string message = error_of(f.write("bad.json", one));
    EXPECT_NE(message.find(needle), std::string::npos) << message;
  };
  expect_frame_error("a 1 0 0 0 1 0 0 0 1 0 0 0\n---\nq 1 0 0 0 1 0 0 0 1 0 0 0\n", "f.txt:3: unknown object 'q'");
  expect_frame_error("a 1 0 0 0 1 0 0 0 1 0 0\n", "f.txt:1: a pose is 12 numbers");
  expect_frame_error("\na 1 0 0 0 1 0 0 0 1 nan 0 0\n", "f.txt:2: object 'a': the pose is not finite");
  expect_frame_error("a 1 0 0 0 1 0 0 0 2 0 0 0\n", "f.txt:1: object 'a': the rotation is not orthonormal");
  expect_frame_error("a 1 0 0 0 1 0 0 0 1 0 0 zero\n", "f.txt:1: 'zero' is not a number");
}

}  // namespace
}  // namespace tightbvh
