// The scene file (JSON) and its frames file (scene_file.hpp).
#include "tightbvh/scene_file.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {

namespace {

using Json = nlohmann::json;

Pose pose_of(const double (&v)[12]) {
  Pose p;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) p.rotation(r, c) = v[3 * r + c];
  p.translation = Vec3(v[9], v[10], v[11]);
  return p;
}

Pose json_pose(const Json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 12) throw InputError(where + ": a pose is 12 numbers (R row-major, then t)");
  double v[12];
  for (int i = 0; i < 12; ++i) {
    if (!j[i].is_number()) throw InputError(where + "[" + std::to_string(i) + "]: not a number");
    v[i] = j[i].get<double>();
  }
  const Pose p = pose_of(v);
  require_valid_pose(p, where, "pose");
  return p;
}

const Json& member(const Json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + ": missing \"" + key + "\"");
  return j.at(key);
}

std::string string_of(const Json& j, const std::string& where) {
  if (!j.is_string()) throw InputError(where + ": not a string");
  return j.get<std::string>();
}

double number_of(const Json& o, const char* key, const std::string& where) {
  const Json& j = member(o, key, where);
  if (!j.is_number()) throw InputError(where + "." + key + ": not a number");
  return j.get<double>();
}

// A convex object's points: "points": [[x, y, z], ...], or "path": a mesh file (resolved against
// the scene file's folder, as models' paths) whose vertices are the points.
std::vector<Vec3> convex_points(const Json& o, const std::string& where, const std::filesystem::path& folder) {
  if (o.contains("points") == o.contains("path"))
    throw InputError(where + ": a convex shape has either \"points\" or \"path\"");
  if (o.contains("path")) {
    const std::filesystem::path mesh_path = folder / string_of(o["path"], where + ".path");
    try {
      return load_mesh(mesh_path).vertices;
    } catch (const InputError& e) {
      throw InputError(where + ".path: " + e.what());
    }
  }
  const Json& points = o["points"];
  if (!points.is_array()) throw InputError(where + ".points: an array of points [x, y, z]");
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Json& p = points[i];
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
      throw InputError(where + ".points[" + std::to_string(i) + "]: three numbers [x, y, z]");
    out.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  }
  return out;
}

// An object's "shape" (with its sizes), the shape.hpp conventions.
Shape shape_of(const Json& o, const std::string& where, const std::filesystem::path& folder) {
  const std::string kind = string_of(member(o, "shape", where), where + ".shape");
  try {
    if (kind == "sphere") return Sphere(number_of(o, "radius", where));
    if (kind == "capsule") return Capsule(number_of(o, "radius", where), number_of(o, "length", where));
    if (kind == "cylinder") return Cylinder(number_of(o, "radius", where), number_of(o, "length", where));
    if (kind == "box") {
      const Json& size = member(o, "size", where);
      if (!size.is_array() || size.size() != 3 || !size[0].is_number() || !size[1].is_number() || !size[2].is_number())
        throw InputError(where + ".size: three numbers [x, y, z] (full side lengths)");
      return Box(size[0].get<double>(), size[1].get<double>(), size[2].get<double>());
    }
    if (kind == "convex") return Convex(convex_points(o, where, folder));
  } catch (const InputError& e) {
    if (std::string(e.what()).starts_with(where)) throw;
    throw InputError(where + ": " + e.what());
  }
  throw InputError(where + ".shape: unknown shape '" + kind + "' (sphere, box, capsule, cylinder, convex)");
}

}  // namespace

std::vector<SceneFrame> load_scene_frames(const std::filesystem::path& path, const Scene& scene) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the frames file");
  std::vector<SceneFrame> frames(1);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string where = path.string() + ":" + std::to_string(number);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "---") {
      frames.emplace_back();
      continue;
    }
    std::istringstream s(line);
    std::string name;
    if (!(s >> name)) continue;  // blank
    const auto id = scene.find(name);
    if (!id) throw InputError(where + ": unknown object '" + name + "'");
    double v[12];
    for (int i = 0; i < 12; ++i) {
      std::string word;
      if (!(s >> word)) throw InputError(where + ": a pose is 12 numbers after the name, got " + std::to_string(i));
      std::size_t used = 0;
      try {
        v[i] = std::stod(word, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != word.size() || used == 0) throw InputError(where + ": '" + word + "' is not a number");
    }
    std::string extra;
    if (s >> extra) throw InputError(where + ": more than 12 numbers after the name");
    const Pose p = pose_of(v);
    require_valid_pose(p, where, "object '" + name + "'");
    frames.back().objects.push_back(*id);
    frames.back().poses.push_back(p);
  }
  // A trailing separator does not open an empty last frame.
  if (frames.size() > 1 && frames.back().objects.empty()) frames.pop_back();
  return frames;
}

SceneFile load_scene_file(const std::filesystem::path& path, const BuildOptions& options) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(file + ": cannot open the scene file");
  Json root;
  try {
    root = Json::parse(in);
  } catch (const Json::parse_error& e) {
    throw InputError(file + ": not valid JSON: " + e.what());
  }
  if (!root.is_object()) throw InputError(file + ": the scene is a JSON object");
  const std::filesystem::path folder = path.parent_path();
  SceneFile out;
  const Json& models = member(root, "models", file);
  if (!models.is_object()) throw InputError(file + ": \"models\" is an object {name: path}");
  for (const auto& [name, value] : models.items()) {
    const std::string where = file + ": models." + name;
    const std::filesystem::path mesh_path = folder / string_of(value, where);
    Mesh mesh;
    try {
      mesh = load_mesh(mesh_path);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    out.models.emplace(name, make_model(std::move(mesh), options));
  }
  const Json& objects = member(root, "objects", file);
  if (!objects.is_array()) throw InputError(file + ": \"objects\" is an array");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const std::string where = file + ": objects[" + std::to_string(i) + "]";
    const Json& o = objects[i];
    SceneObject object;
    object.name = string_of(member(o, "name", where), where + ".name");
    if (object.name.empty()) throw InputError(where + ".name: empty");
    if (o.contains("model") == o.contains("shape"))
      throw InputError(where + ": an object has either \"model\" or \"shape\"");
    if (o.contains("shape")) {
      object.shape = shape_of(o, where, folder);
    } else {
      const std::string model = string_of(member(o, "model", where), where + ".model");
      const auto it = out.models.find(model);
      if (it == out.models.end()) throw InputError(where + ".model: unknown model '" + model + "'");
      object.model = it->second;
    }
    object.pose = json_pose(member(o, "pose", where), where + ".pose");
    if (out.scene.find(object.name)) throw InputError(where + ".name: duplicate name '" + object.name + "'");
    (void)out.scene.add(std::move(object));
  }
  if (root.contains("allowed")) {
    const Json& allowed = root["allowed"];
    if (!allowed.is_array()) throw InputError(file + ": \"allowed\" is an array of name pairs");
    for (std::size_t i = 0; i < allowed.size(); ++i) {
      const std::string where = file + ": allowed[" + std::to_string(i) + "]";
      if (!allowed[i].is_array() || allowed[i].size() != 2) throw InputError(where + ": a pair [name, name]");
      ObjectId ids[2];
      for (int k = 0; k < 2; ++k) {
        const std::string name = string_of(allowed[i][k], where);
        const auto id = out.scene.find(name);
        if (!id) throw InputError(where + ": unknown object '" + name + "'");
        ids[k] = *id;
      }
      if (ids[0] == ids[1]) throw InputError(where + ": an object with itself");
      out.scene.allow(ids[0], ids[1]);
    }
  }
  if (root.contains("frames")) {
    const std::string frames = string_of(root["frames"], file + ": frames");
    out.frames = load_scene_frames(folder / frames, out.scene);
  }
  return out;
}

}  // namespace tightbvh
