#include "view/scene.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "tightbvh/tree_walk.hpp"

namespace tightbvh::view {
namespace {

// Drawing needs about five significant digits of the scene's size. Numbers rounded to a power of
// ten print short: nlohmann-json writes the shortest text that reads back the same double, and
// k / 10^n (correctly rounded) reads back from the text of k * 10^-n.
class Rounding {
 public:
  explicit Rounding(double scale)
      : exponent_(std::isfinite(scale) && scale > 0 ? 5 - static_cast<int>(std::floor(std::log10(scale))) : 5),
        power_(std::pow(10.0, std::abs(exponent_))) {}
  [[nodiscard]] double operator()(double v) const {
    return exponent_ >= 0 ? std::round(v * power_) / power_ : std::round(v / power_) * power_;
  }
  void append(nlohmann::json& out, const Vec3& v) const {
    for (int i = 0; i < 3; ++i) out.push_back((*this)(v[i]));
  }

 private:
  int exponent_;
  double power_;
};

// The size of a scene with these points: the largest coordinate or extent.
double scale_of(const Aabb& bounds) {
  return bounds.empty() ? 1.0 : std::max(bounds.min.cwiseAbs().maxCoeff(), bounds.max.cwiseAbs().maxCoeff());
}
double scale_of(const Obb& box) { return std::max(box.center.cwiseAbs().maxCoeff(), box.half_extents.maxCoeff()); }

void append_box(nlohmann::json& out, const Obb& box, const Rounding& positions) {
  static const Rounding unit(1.0);  // the axes
  positions.append(out, box.center);
  for (int axis = 0; axis < 3; ++axis) unit.append(out, box.axes.col(axis));
  positions.append(out, box.half_extents);
}

// The corners of the listed triangles, 9 numbers each, after `pose`.
nlohmann::json corners_json(const Mesh& mesh, const std::set<std::uint32_t>& triangles, const Pose& pose) {
  const Rounding rounding(scale_of(bounds_of(mesh.vertices).transformed(pose)));
  nlohmann::json out = nlohmann::json::array();
  for (const std::uint32_t t : triangles)
    for (const Vec3& c : mesh.corners(t)) rounding.append(out, pose.apply(c));
  return out;
}

}  // namespace

nlohmann::json mesh_json(const Mesh& mesh, const Pose& pose, std::size_t max_triangles) {
  const DrawnMesh drawn = decimate_for_drawing(mesh, max_triangles);
  const Rounding rounding(scale_of(bounds_of(mesh.vertices).transformed(pose)));
  nlohmann::json positions = nlohmann::json::array();
  for (const Vec3& v : drawn.mesh.vertices) rounding.append(positions, pose.apply(v));
  nlohmann::json indices = nlohmann::json::array();
  for (const Triangle& t : drawn.mesh.triangles)
    for (const std::uint32_t i : t) indices.push_back(i);
  return {{"triangles", mesh.triangles.size()}, {"drawn_triangles", drawn.mesh.triangles.size()},
          {"decimated", drawn.decimated},       {"max_drawn_triangles", max_triangles},
          {"positions", std::move(positions)},  {"indices", std::move(indices)}};
}

nlohmann::json box_json(const Obb& box) {
  nlohmann::json out = nlohmann::json::array();
  append_box(out, box, Rounding(scale_of(box)));
  return out;
}

nlohmann::json tree_json(const std::string& fitter, const BuildResult& built, std::size_t level,
                         std::size_t max_boxes) {
  const TreeStats& stats = built.stats.tree;
  std::vector<std::size_t> boxes_per_level(stats.volume_per_level.size(), 0);
  for_each_node(built.tree, [&](const NodeVisit& v) { ++boxes_per_level[v.depth]; });
  std::size_t drawn_levels = 0;
  for (std::size_t boxes = 0; drawn_levels < boxes_per_level.size(); ++drawn_levels) {
    boxes += boxes_per_level[drawn_levels];
    if (boxes > max_boxes && drawn_levels > level) break;
  }
  nlohmann::json levels(drawn_levels, nlohmann::json::array());
  // The root's box holds the mesh (an empty tree has no levels).
  const Rounding rounding(built.tree.nodes.empty() ? 1.0 : scale_of(built.tree.nodes[0].box.obb()));
  for_each_node(built.tree, [&](const NodeVisit& v) {
    if (v.depth >= drawn_levels) return false;
    append_box(levels[v.depth], v.node.box.obb(), rounding);
    return true;
  });
  return {{"fitter", fitter},
          {"seconds", built.stats.seconds},
          {"sum_volume", stats.sum_volume},
          {"volume_per_level", stats.volume_per_level},
          {"boxes_per_level", boxes_per_level},
          {"levels", std::move(levels)}};
}

nlohmann::json trees_scene(const std::string& title, const Mesh& mesh, std::size_t level, nlohmann::json trees) {
  return {
      {"kind", "trees"}, {"title", title}, {"mesh", mesh_json(mesh)}, {"level", level}, {"trees", std::move(trees)}};
}

nlohmann::json contacts_scene(const std::string& title, const ContactInput& input) {
  std::set<std::uint32_t> touching_a, touching_b;
  for (const TrianglePair& p : input.result.pairs) {
    touching_a.insert(p.a);
    touching_b.insert(p.b);
  }
  const nlohmann::json result = {{"mode", input.all_pairs ? "all_pairs" : "first_hit"},
                                 {"hit", input.result.hit},
                                 {"pairs", input.result.pairs.size()},
                                 {"box_tests", input.result.stats.box_tests},
                                 {"triangle_tests", input.result.stats.triangle_tests}};
  nlohmann::json scene = {
      {"kind", "contacts"},
      {"title", title},
      {"meshes", {mesh_json(input.a), mesh_json(input.b, input.pose_b)}},
      {"contacts", {corners_json(input.a, touching_a, Pose{}), corners_json(input.b, touching_b, input.pose_b)}},
      {"result", result}};
  if (!input.result.contacts.empty()) {  // the intersection curve: its segments' ends, 6 numbers each
    nlohmann::json curve = nlohmann::json::array();
    for (const Contact& c : input.result.contacts)
      if (c.kind == ContactKind::segment)
        for (int i = 0; i < 2; ++i)
          for (int k = 0; k < 3; ++k) curve.push_back(c.points[static_cast<std::size_t>(i)][k]);
    scene["curve"] = std::move(curve);
    scene["result"]["curve_length"] = input.result.curve_length;
  }
  return scene;
}

nlohmann::json distance_scene(const std::string& title, const DistanceInput& input) {
  const DistanceResult& r = input.result;
  std::set<std::uint32_t> closest_a, closest_b;
  nlohmann::json closest = nlohmann::json::array();
  if (!r.beyond_upper_bound) {
    if (r.inside == Inside::none) {
      closest_a.insert(r.pair.a);
      closest_b.insert(r.pair.b);
    }
    // Full precision: the segment may be far shorter than the scene's rounding step.
    for (const Vec3& p : {r.point_a, r.point_b}) closest.insert(closest.end(), {p.x(), p.y(), p.z()});
  }
  const nlohmann::json result = {{"distance", r.distance},
                                 {"beyond_upper_bound", r.beyond_upper_bound},
                                 {"inside", to_string(r.inside)},
                                 {"node_pairs", r.stats.node_pairs},
                                 {"triangle_pairs", r.stats.triangle_pairs}};
  return {{"kind", "distance"},
          {"title", title},
          {"meshes", {mesh_json(input.a), mesh_json(input.b, input.pose_b)}},
          {"contacts", {corners_json(input.a, closest_a, Pose{}), corners_json(input.b, closest_b, input.pose_b)}},
          {"closest", std::move(closest)},
          {"result", result}};
}

nlohmann::json descent_json(const CollideTrace& trace, const Tree& a, const Tree& b, const Pose& pose_b,
                            std::size_t max_pairs) {
  const std::size_t drawn = std::min(max_pairs, trace.pairs.size());
  // One rounding for both trees (the scene's size), as for the meshes.
  double scale = 1.0;
  if (!a.nodes.empty() && !b.nodes.empty())
    scale = std::max(scale_of(a.nodes[0].box.obb()), scale_of(b.nodes[0].box.obb().transformed(pose_b)));
  const Rounding rounding(scale);
  nlohmann::json boxes_a = nlohmann::json::array(), boxes_b = nlohmann::json::array();
  std::map<std::uint32_t, std::size_t> index_a, index_b;  // node -> position in boxes_a / boxes_b
  const auto box_index = [&](std::map<std::uint32_t, std::size_t>& index, nlohmann::json& boxes, const Obb& box,
                             std::uint32_t node) {
    const auto [it, added] = index.try_emplace(node, index.size());
    if (added) append_box(boxes, box, rounding);
    return it->second;
  };
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t i = 0; i < drawn; ++i) {
    const VisitedPair& p = trace.pairs[i];
    steps.push_back(box_index(index_a, boxes_a, a.nodes[p.a].box.obb(), p.a));
    steps.push_back(box_index(index_b, boxes_b, b.nodes[p.b].box.obb().transformed(pose_b), p.b));
    steps.push_back(static_cast<int>(p.outcome));
    steps.push_back(p.level);
  }
  return {{"visited", trace.visited},          {"drawn", drawn},   {"max_drawn", max_pairs},
          {"per_level", trace.per_level},      {"boxes_a", std::move(boxes_a)},
          {"boxes_b", std::move(boxes_b)},     {"steps", std::move(steps)}};
}

}  // namespace tightbvh::view
