#include "tightbvh/validate_tree.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <utility>

namespace tightbvh {
namespace {

struct Range {
  std::size_t begin = 0;
  std::size_t end = 0;
};

class Checker {
 public:
  Checker(const Tree& tree, std::size_t max_errors) : tree_(tree), max_errors_(max_errors) {}

  [[nodiscard]] bool full() const { return check_.errors.size() >= max_errors_; }
  [[nodiscard]] bool ok() const { return check_.ok(); }

  template <class... Parts>
  void error(const Parts&... parts) {
    if (full()) return;
    std::ostringstream out;
    out.precision(17);
    (out << ... << parts);
    check_.errors.push_back(out.str());
  }

  // Fills ranges_ (and depth_) if the structure is sound.
  void structure() {
    const auto& nodes = tree_.nodes;
    const auto& order = tree_.triangle_order;
    if (nodes.empty()) return error("tree has no nodes");
    if (nodes.size() > std::numeric_limits<std::uint32_t>::max())
      return error("tree has ", nodes.size(), " nodes, more than 32-bit indices allow");

    std::vector<char> seen(order.size(), 0);
    for (std::size_t i = 0; i < order.size() && !full(); ++i) {
      const std::uint32_t t = order[i];
      if (t >= order.size())
        error("triangle_order[", i, "] = ", t, " is out of range (", order.size(), " triangles)");
      else if (seen[t]++)
        error("triangle ", t, " appears more than once in triangle_order (again at ", i, ")");
    }

    for (std::size_t i = 0; i < nodes.size() && !full(); ++i) box(i, nodes[i].box.obb());

    // Depth-first from the root: every node reached exactly once. Not for_each_node
    // (tree_walk.hpp): that walk trusts the structure this one checks, a cycle would never end.
    std::vector<char> visited(nodes.size(), 0);
    std::vector<std::uint32_t> preorder;
    preorder.reserve(nodes.size());
    depth_.assign(nodes.size(), 0);
    std::vector<std::uint32_t> stack{0};
    visited[0] = 1;
    while (!stack.empty() && !full()) {
      const std::uint32_t i = stack.back();
      stack.pop_back();
      preorder.push_back(i);
      const Node& node = nodes[i];
      if (node.is_leaf()) {
        if (std::uint64_t{node.first} + node.count > order.size())
          error("node ", i, ": leaf range [", node.first, ", ", std::uint64_t{node.first} + node.count,
                ") exceeds triangle_order (", order.size(), " entries)");
        continue;
      }
      if (std::uint64_t{node.first} + 1 >= nodes.size()) {
        error("node ", i, ": children ", node.first, ", ", std::uint64_t{node.first} + 1,
              " out of range (", nodes.size(), " nodes)");
        continue;
      }
      for (const std::uint32_t child : {node.first, node.first + 1}) {
        if (visited[child]) {
          error("node ", child, " is reached twice (cycle or shared child), again from node ", i);
          continue;
        }
        visited[child] = 1;
        depth_[child] = depth_[i] + 1;
        stack.push_back(child);
      }
    }
    if (!check_.ok()) return;
    if (preorder.size() != nodes.size()) {
      for (std::size_t i = 0; i < nodes.size(); ++i)
        if (!visited[i]) error("node ", i, " is not reachable from the root (",
                               nodes.size() - preorder.size(), " unreachable nodes)");
      return;
    }

    // Triangle ranges bottom-up (reverse preorder visits children before parents); as
    // triangle_ranges (tree_walk.hpp), but checking that the children's ranges are adjacent.
    ranges_.assign(nodes.size(), {});
    for (auto it = preorder.rbegin(); it != preorder.rend() && !full(); ++it) {
      const Node& node = nodes[*it];
      if (node.is_leaf()) {
        ranges_[*it] = {node.first, std::size_t{node.first} + node.count};
        continue;
      }
      const Range& l = ranges_[node.first];
      const Range& r = ranges_[node.first + 1];
      if (l.end != r.begin)
        error("node ", *it, ": children's triangle ranges [", l.begin, ", ", l.end, ") and [", r.begin, ", ",
              r.end, ") do not partition a contiguous range");
      ranges_[*it] = {l.begin, r.end};
    }
    if (check_.ok() && (ranges_[0].begin != 0 || ranges_[0].end != order.size()))
      error("root covers triangle_order[", ranges_[0].begin, ", ", ranges_[0].end, ") instead of [0, ",
            order.size(), ")");
  }

  void containment(const Mesh& mesh) {
    const auto& order = tree_.triangle_order;
    if (order.size() != mesh.triangles.size())
      return error("tree has ", order.size(), " triangles, the mesh ", mesh.triangles.size());
    for (const Triangle& t : mesh.triangles)
      for (const std::uint32_t v : t)
        if (v >= mesh.vertices.size()) return error("mesh: vertex index ", v, " out of range");
    for (std::size_t i = 0; i < tree_.nodes.size() && !full(); ++i) {
      const Obb box = tree_.nodes[i].box.obb();
      const double tolerance = containment_tolerance(box);
      for (std::size_t k = ranges_[i].begin; k < ranges_[i].end; ++k) {
        const Triangle& t = mesh.triangles[order[k]];
        for (const std::uint32_t v : t) {
          if (box.contains(mesh.vertices[v], tolerance)) continue;
          const Vec3 outside = box.to_local(mesh.vertices[v]).cwiseAbs() - box.half_extents;
          error("node ", i, " (depth ", depth_[i], ", ", ranges_[i].end - ranges_[i].begin,
                " triangles): box does not contain vertex ", v, " of triangle ", order[k], ": ",
                outside.maxCoeff(), " outside, tolerance ", tolerance);
          k = ranges_[i].end;  // one error per node
          break;
        }
      }
    }
  }

  [[nodiscard]] TreeCheck result() && { return std::move(check_); }

 private:
  void box(std::size_t i, const Obb& b) {
    if (!b.center.allFinite() || !b.axes.allFinite() || !b.half_extents.allFinite())
      return error("node ", i, ": box has a non-finite value");
    if ((b.half_extents.array() < 0.0).any()) return error("node ", i, ": box has a negative half extent");
    const double skew = (b.axes.transpose() * b.axes - Mat3::Identity()).cwiseAbs().maxCoeff();
    if (skew > 1e-6) return error("node ", i, ": box axes are not orthonormal (|A^T A - I| = ", skew, ")");
    if (b.axes.determinant() < 0.0) return error("node ", i, ": box axes are left-handed");
  }

  const Tree& tree_;
  std::size_t max_errors_;
  TreeCheck check_;
  std::vector<Range> ranges_;
  std::vector<std::size_t> depth_;
};

}  // namespace

std::string TreeCheck::summary() const {
  std::string out;
  for (const std::string& e : errors) out += e + '\n';
  return out;
}

TreeCheck check_structure(const Tree& tree) {
  Checker checker(tree, 20);
  checker.structure();
  return std::move(checker).result();
}

TreeCheck validate(const Tree& tree, const Mesh& mesh, std::size_t max_errors) {
  Checker checker(tree, max_errors == 0 ? 1 : max_errors);
  checker.structure();
  if (checker.ok()) checker.containment(mesh);  // needs the ranges, i.e. a sound structure
  return std::move(checker).result();
}

}  // namespace tightbvh
