// Tree-vs-tree collision queries (Gottschalk, Lin & Manocha 1996 descent; SAT box test;
// Guigue-Devillers triangle test). See include/tightbvh/collide.hpp.
#include "tightbvh/collide.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <thread>

#include "../tree/parallel.hpp"
#include "query_workspace.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tri_tri.hpp"
#include "traverse.hpp"

namespace tightbvh {
namespace {

// B's vertex in A's frame. Written out so that collide() and collide_brute_force() evaluate
// exactly the same expression (same operation order) and hence see the same triangles.
[[nodiscard]] inline Vec3 map_point(const Pose& rel, const Vec3& v) {
  const Mat3& r = rel.rotation;
  const Vec3& t = rel.translation;
  return {r(0, 0) * v.x() + r(0, 1) * v.y() + r(0, 2) * v.z() + t.x(),
          r(1, 0) * v.x() + r(1, 1) * v.y() + r(1, 2) * v.z() + t.y(),
          r(2, 0) * v.x() + r(2, 1) * v.y() + r(2, 2) * v.z() + t.z()};
}

[[nodiscard]] double box_scale(const Obb& box) {
  return box.center.cwiseAbs().maxCoeff() + box.half_extents.cwiseAbs().maxCoeff();
}

// Number of B triangles mapped into A's frame at once in a leaf-leaf test.
constexpr std::uint32_t kLeafChunk = 32;

template <bool FirstHit>
void collide_trees(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb, const Pose& rel,
                   DescendRule rule, QueryWorkspace::Scratch& ws, QueryResult& result) {
  using namespace query_detail;
  const Mat3& R = rel.rotation;
  const Vec3& t = rel.translation;
  const double margin = kBoxMargin * (box_scale(ta.nodes[0].box) + box_scale(tb.nodes[0].box) +
                                      t.cwiseAbs().maxCoeff());
  std::uint64_t box_tests = 0, triangle_tests = 0;
  BoxCache& cache = ws.mapped_b;
  cache.begin(tb.nodes.size());
  const auto boxes_overlap = [&](std::uint32_t ia, std::uint32_t ib) {
    const Obb& ba = ta.nodes[ia].box;
    const Obb& bb = tb.nodes[ib].box;
    // B's box in A's frame (cached), then in A's box frame: C = Aa^T (R Bb), Aa^T (R cb + t - ca).
    ++box_tests;
    MappedBox& mapped_box = cache.boxes[ib];
    if (cache.stamp[ib] != cache.epoch) {
      cache.stamp[ib] = cache.epoch;
      mapped_box.axes.noalias() = R * bb.axes;
      mapped_box.center.noalias() = R * bb.center + t;
    }
    const Mat3 c = ba.axes.transpose() * mapped_box.axes;
    const Vec3 d = ba.axes.transpose() * (mapped_box.center - ba.center);
    return obb_overlap(c, d, ba.half_extents, bb.half_extents, margin);
  };
  std::array<std::array<Vec3, 3>, kLeafChunk> mapped;
  const auto triangles_touch = [&](std::uint32_t ia_node, std::uint32_t ib_node) {
    const Node& na = ta.nodes[ia_node];
    const Node& nb = tb.nodes[ib_node];
    for (std::uint32_t cb = 0; cb < nb.count; cb += kLeafChunk) {
      const std::uint32_t nbc = std::min(kLeafChunk, nb.count - cb);
      for (std::uint32_t j = 0; j < nbc; ++j) {
        const Triangle& tri = mb.triangles[tb.triangle_order[nb.first + cb + j]];
        for (int k = 0; k < 3; ++k) mapped[j][k] = map_point(rel, mb.vertices[tri[k]]);
      }
      for (std::uint32_t i = 0; i < na.count; ++i) {
        const std::uint32_t ia = ta.triangle_order[na.first + i];
        const Triangle& tri = ma.triangles[ia];
        const Vec3& p0 = ma.vertices[tri[0]];
        const Vec3& p1 = ma.vertices[tri[1]];
        const Vec3& p2 = ma.vertices[tri[2]];
        for (std::uint32_t j = 0; j < nbc; ++j) {
          ++triangle_tests;
          if (tri_tri_overlap(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2])) {
            result.hit = true;
            result.pairs.push_back({ia, tb.triangle_order[nb.first + cb + j]});
            if constexpr (FirstHit) return Walk::stop;
          }
        }
      }
    }
    return Walk::go_on;
  };
  traverse_pairs(ta, tb, rule, ws.stack, boxes_overlap, triangles_touch);
  result.stats.box_tests += box_tests;
  result.stats.triangle_tests += triangle_tests;
}

// O(1) guard against the common mistake of pairing a tree with another mesh, which would
// otherwise index out of range in the leaves. (Full checking is validate(tree, mesh).)
void check_tree_fits_mesh(const Tree& tree, const Mesh& mesh, const char* which) {
  if (tree.triangle_order.size() != mesh.triangles.size())
    throw InputError(std::string("collide: tree ") + which + " was built over " +
                     std::to_string(tree.triangle_order.size()) + " triangles but mesh " + which + " has " +
                     std::to_string(mesh.triangles.size()));
}

void finish(QueryResult& result) {
  std::sort(result.pairs.begin(), result.pairs.end());
  result.pairs.erase(std::unique(result.pairs.begin(), result.pairs.end()), result.pairs.end());
}

}  // namespace

Pose relative_pose(const Pose& pa, const Pose& pb) { return pa.inverse() * pb; }

QueryWorkspace::QueryWorkspace() : scratch_(std::make_unique<Scratch>()) {}
QueryWorkspace::~QueryWorkspace() = default;
QueryWorkspace::QueryWorkspace(QueryWorkspace&&) noexcept = default;
QueryWorkspace& QueryWorkspace::operator=(QueryWorkspace&&) noexcept = default;

QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                    const QueryOptions& options, QueryWorkspace& workspace) {
  QueryResult result;
  if (a.nodes.empty() || b.nodes.empty()) return result;
  check_tree_fits_mesh(a, ma, "A");
  check_tree_fits_mesh(b, mb, "B");
  const Pose rel = relative_pose(pa, pb);
  if (options.mode == QueryMode::first_hit) {
    collide_trees<true>(a, ma, b, mb, rel, options.descend, workspace.scratch(), result);
  } else {
    collide_trees<false>(a, ma, b, mb, rel, options.descend, workspace.scratch(), result);
    finish(result);
  }
  return result;
}

QueryResult collide(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb, const Pose& pb,
                    const QueryOptions& options) {
  QueryWorkspace workspace;
  return collide(a, ma, pa, b, mb, pb, options, workspace);
}

std::vector<QueryResult> collide_batch(const Tree& a, const Mesh& ma, const Pose& pa, const Tree& b, const Mesh& mb,
                                       std::span<const Pose> poses_b, const QueryOptions& options, unsigned threads) {
  std::vector<QueryResult> results(poses_b.size());
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(poses_b.size(), 1)));
  // The builder's pool: dynamic scheduling over pose indices, one workspace per worker, each
  // result in its own slot (so the output does not depend on the thread count or the
  // interleaving), and the error of the lowest failing pose rethrown.
  detail::WorkerPool<QueryWorkspace> pool(threads);
  pool.run(poses_b.size(), [&](std::size_t i, QueryWorkspace& workspace) {
    results[i] = collide(a, ma, pa, b, mb, poses_b[i], options, workspace);
  });
  return results;
}

QueryResult collide_brute_force(const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb,
                                const QueryOptions& options) {
  QueryResult result;
  const Pose rel = relative_pose(pa, pb);
  std::vector<Vec3> mapped(mb.vertices.size());
  for (std::size_t i = 0; i < mb.vertices.size(); ++i) mapped[i] = map_point(rel, mb.vertices[i]);
  for (std::uint32_t ia = 0; ia < ma.triangles.size(); ++ia) {
    const auto [p0, p1, p2] = ma.corners(ia);
    for (std::uint32_t ib = 0; ib < mb.triangles.size(); ++ib) {
      const Triangle& t = mb.triangles[ib];
      ++result.stats.triangle_tests;
      if (tri_tri_overlap(p0, p1, p2, mapped[t[0]], mapped[t[1]], mapped[t[2]])) {
        result.hit = true;
        result.pairs.push_back({ia, ib});
        if (options.mode == QueryMode::first_hit) return result;
      }
    }
  }
  return result;  // already sorted and unique
}

}  // namespace tightbvh
