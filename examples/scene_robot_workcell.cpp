// A robot arm of box links in a workcell (a table, a post, a part on the table): self-collision of
// the arm with neighbouring links allowed to touch, the arm against the workcell, the clearance to
// the nearest obstacle, and a gripper padded by a sphere at the arm's tip (a shape, no mesh), for
// a few joint angles.
//   scene_robot_workcell
#include <tightbvh/mesh.hpp>
#include <tightbvh/model.hpp>
#include <tightbvh/scene.hpp>
#include <tightbvh/shape.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <vector>

namespace {

// An axis-aligned box mesh from `lo` to `hi`, triangles facing out.
tightbvh::Mesh box(const tightbvh::Vec3& lo, const tightbvh::Vec3& hi) {
  tightbvh::Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

}  // namespace

int main() try {
  using namespace tightbvh;
  // Models are built once and shared: every link uses the same one.
  const ModelPtr link = make_model(box(Vec3(0, -0.05, -0.05), Vec3(0.5, 0.05, 0.05)));
  const ModelPtr table = make_model(box(Vec3(-1, -1, -0.1), Vec3(1, 1, 0)));
  const ModelPtr post = make_model(box(Vec3(-0.05, -0.05, 0), Vec3(0.05, 0.05, 1.5)));
  const ModelPtr part = make_model(load_mesh(TIGHTBVH_SOURCE_DIR "/meshes/knot1.off"));

  Scene cell;
  cell.add(table, Pose{}, "table");
  Pose at;
  at.translation = Vec3(0.8, 0.0, 0.0);
  cell.add(post, at, "post");
  at.translation = Vec3(0.0, 0.8, 0.25);  // the knot is about 1 x 1 x 0.5
  cell.add(part, at, "part");

  // Four links in a chain; neighbours share a joint, so they may touch.
  Scene arm;
  std::vector<ObjectId> links;
  for (int i = 0; i < 4; ++i) links.push_back(arm.add(link, Pose{}, "link" + std::to_string(i)));
  for (int i = 0; i + 1 < 4; ++i) arm.allow(links[i], links[i + 1]);

  bool agree = true;  // each answer checked against the pair queries on every object pair
  for (const double bend : {0.3, 1.2, 2.6}) {
    // Forward kinematics: each link turns by `bend` about z at the end of the previous one.
    Pose joint;
    joint.translation = Vec3(0.0, 0.0, 0.3);
    std::vector<Pose> poses;
    for (int i = 0; i < 4; ++i) {
      poses.push_back(joint);
      Pose next;
      next.rotation = Eigen::AngleAxisd(bend, Vec3::UnitZ()).toRotationMatrix();
      next.translation = Vec3(0.5, 0.0, 0.0);
      joint = joint * next;
    }
    arm.set_poses(links, poses);

    const std::vector<ObjectPairHit> self = collide(arm);
    const std::vector<ObjectPairHit> cell_hits = collide(arm, cell);
    const std::optional<ObjectPairDistance> nearest = distance(arm, cell);
    std::printf("bend %.1f: %zu self-collisions, %zu arm-workcell collisions", bend, self.size(), cell_hits.size());
    for (const ObjectPairHit& hit : cell_hits)
      std::printf(" [%s-%s]", arm.object(hit.a).name.c_str(), cell.object(hit.b).name.c_str());
    for (const ObjectPairHit& hit : self)
      std::printf(" [%s-%s]", arm.object(hit.a).name.c_str(), arm.object(hit.b).name.c_str());
    if (nearest)
      std::printf(", clearance %.3f (%s to %s)", nearest->result.distance, arm.object(nearest->a).name.c_str(),
                  cell.object(nearest->b).name.c_str());
    // The gripper: a sphere of radius 0.15 at the tip, queried against the workcell as it is.
    const Shape gripper = Sphere(0.15);
    const std::vector<ObjectHit> grasped = collide(cell, gripper, joint);
    const std::optional<ObjectDistance> gap = distance(cell, gripper, joint);
    std::printf("; gripper touches %zu, clearance %.3f\n", grasped.size(), gap ? gap->result.distance : -1.0);

    std::size_t expected = 0, expected_grasped = 0;
    double expected_gap = 1e300;
    for (const ObjectId b : cell.ids()) {
      const SceneObject& o = cell.object(b);
      expected_grasped += collide(std::get<Sphere>(gripper), joint, *o.model, o.pose).hit;
      expected_gap = std::min(expected_gap, distance(std::get<Sphere>(gripper), joint, *o.model, o.pose).distance);
    }
    agree = agree && expected_grasped == grasped.size() && gap && gap->result.distance == expected_gap;
    for (const ObjectId a : arm.ids())
      for (const ObjectId b : cell.ids())
        expected += collide(*arm.object(a).model, arm.object(a).pose, *cell.object(b).model, cell.object(b).pose).hit;
    for (const ObjectId a : arm.ids())
      for (const ObjectId b : arm.ids())
        if (a < b && !arm.allowed(a, b))
          expected += collide(*arm.object(a).model, arm.object(a).pose, *arm.object(b).model, arm.object(b).pose).hit;
    agree = agree && expected == self.size() + cell_hits.size();
  }
  if (!agree) return 1;
  std::printf("the scene answers equal the pair queries on every object pair\n");
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "scene_robot_workcell: %s\n", e.what());
  return 1;
}
