#pragma once
/// @file
/// The scene file: a JSON description of a scene (models, posed objects, allowed pairs) and an
/// optional frames file of moves, for the CLI (`tightbvh scene`), the benchmark and other tools.
///
///     {"models": {"NAME": "PATH.off", ...},        paths relative to the scene file's folder
///      "objects": [{"name": "obj0", "model": "NAME",
///                   "pose": [r00,r01,r02,r10,r11,r12,r20,r21,r22,tx,ty,tz]},
///                  {"name": "ball", "shape": "sphere", "radius": R, "pose": [...]},
///                  {"name": "crate", "shape": "box", "size": [X, Y, Z], "pose": [...]},
///                  {"name": "link", "shape": "capsule", "radius": R, "length": L, "pose": [...]}, ...],
///      "allowed": [["obj0", "obj1"], ...],         optional: pairs never reported
///      "frames": "FRAMES.txt"}                     optional: moves, below
///
/// An object has a "model" or a "shape" (shape.hpp: FCL's conventions; "size" the box's full
/// side lengths, "length" the capsule's axis segment, along its local z). A pose is the object's
/// world pose, x_world = R x_model + t, R row-major. The frames file holds
/// frames separated by a line holding only `---`; within a frame, one line per moved object,
/// `NAME r00 ... tz` (its new world pose). Blank lines are ignored.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tightbvh/build.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/pose.hpp"
#include "tightbvh/scene.hpp"

namespace tightbvh {

/// One frame of moves: objects[i] goes to poses[i] (Scene::set_poses takes both).
struct SceneFrame {
  std::vector<ObjectId> objects;  ///< the moved objects
  std::vector<Pose> poses;        ///< their new world poses
};

/// A loaded scene file.
struct SceneFile {
  Scene scene;                              ///< the objects at their initial poses, allowed pairs set
  std::map<std::string, ModelPtr> models;   ///< the models by their name in the file
  std::vector<SceneFrame> frames;           ///< the frames file's moves, in order (empty without one)
};

/// Loads a scene file and its meshes (load_mesh), building each model's tree with `options`.
/// Throws InputError naming the file and the key or line: a missing or malformed file, an
/// unknown key type, an unknown model, shape or object name, an object with both or neither of a
/// model and a shape, a shape size that is missing, not positive or not finite, a duplicate
/// object name, a pose that is not 12 numbers, not finite, or whose rotation is not orthonormal
/// within 1e-6.
[[nodiscard]] SceneFile load_scene_file(const std::filesystem::path& path, const BuildOptions& options = {});

/// Reads a frames file for `scene` (object names resolved in it); the same errors, naming the line.
[[nodiscard]] std::vector<SceneFrame> load_scene_frames(const std::filesystem::path& path, const Scene& scene);

}  // namespace tightbvh
