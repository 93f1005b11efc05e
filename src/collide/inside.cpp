// Point in solid by exact ray parity, and the solid part of collide() and distance(). See
// include/tightbvh/inside.hpp and src/collide/solid.hpp.
#include "tightbvh/inside.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "../geometry/predicates.hpp"
#include "box_bounds4.hpp"
#include "query_common.hpp"
#include "solid.hpp"
#include "wide_nodes.hpp"

namespace tightbvh {
namespace {

using detail::orient2d;
using detail::orient3d;

// A node's float box in double (exact conversion). Its axes are orthonormal only to ~2e-7, but
// the box is the slab box { x : |a_i . (x - c)| <= e_i } of exactly these axes (compact_box.hpp),
// which is what the slab test below evaluates: only the transforms' rounding needs a margin.
[[nodiscard]] Obb box_of(const Node& node) { return node.box.obb(); }

// p on the closed segment uv (exact).
[[nodiscard]] bool on_segment(const Vec3& u, const Vec3& v, const Vec3& p) {
  if (!detail::collinear(u, v, p)) return false;
  for (int k = 0; k < 3; ++k)
    if (p[k] < std::min(u[k], v[k]) || p[k] > std::max(u[k], v[k])) return false;
  return true;
}

// p, which lies in the plane of a, b, c (orient3d == 0), in the closed triangle (exact): in a
// coordinate projection where the triangle is not flat (the projection is then one-to-one on
// the plane), or on one of its edges when a, b, c are collinear.
[[nodiscard]] bool in_closed_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  for (const int k : {2, 0, 1}) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const int o = orient2d(a[i], a[j], b[i], b[j], c[i], c[j]);
    if (o == 0) continue;
    return orient2d(a[i], a[j], b[i], b[j], p[i], p[j]) != -o && orient2d(b[i], b[j], c[i], c[j], p[i], p[j]) != -o &&
           orient2d(c[i], c[j], a[i], a[j], p[i], p[j]) != -o;
  }
  return on_segment(a, b, p) || on_segment(b, c, p) || on_segment(c, a, p);
}

enum class Meet : std::uint8_t { miss, cross, degenerate, on_surface };

// How the segment pq meets the closed triangle abc, exactly. `cross`: through the interior,
// transversally (p and q strictly on opposite sides of the plane, the line strictly inside the
// three edges: orient3d(p, q, edge) of one strict sign, Pluecker's side test). `miss`: the
// segment stays strictly on one side of the plane, or the line passes strictly outside an edge
// (mixed strict signs; this covers lines parallel to the plane). `on_surface`: p is on the
// triangle. Anything else (the line through an edge or a vertex, in the plane, an endpoint on
// the plane) is `degenerate`: the caller re-shoots.
[[nodiscard]] Meet meet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, const Vec3& q) {
  const detail::OrientPlane plane(a, b, c);
  const int sp = plane.sign(p);
  if (sp == 0 && in_closed_triangle(a, b, c, p)) return Meet::on_surface;
  const int sq = plane.sign(q);
  if (sp * sq > 0) return Meet::miss;
  const int e0 = orient3d(p, q, a, b), e1 = orient3d(p, q, b, c), e2 = orient3d(p, q, c, a);
  if ((e0 > 0 || e1 > 0 || e2 > 0) && (e0 < 0 || e1 < 0 || e2 < 0)) return Meet::miss;
  if (sp * sq < 0 && e0 != 0 && e1 != 0 && e2 != 0) return Meet::cross;
  return Meet::degenerate;
}

// May the segment pq (frame of the tree) meet the box? The separating-axis test of a segment
// and a box (Ericson, Real-Time Collision Detection §5.3.3, TestSegmentAABB) in the box's frame:
// the box's three face normals, then the three products of an axis with the segment's
// direction; no division. On the box inflated by `margin`, which absorbs the rounding of the
// transforms (and of the midpoint and half-vector), so a triangle the segment meets is never
// culled; the edge axes' products also get their own rounding (a few ulps of each product) on
// the side that keeps the box.
[[nodiscard]] bool segment_meets_box(const Obb& box, const Vec3& p, const Vec3& q, double margin) {
  const Vec3 m = box.to_local(0.5 * (p + q));
  const Vec3 w = box.axes.transpose() * (0.5 * (q - p));
  const Vec3 aw = w.cwiseAbs();
  const Vec3 h = box.half_extents.array() + margin;
  for (int k = 0; k < 3; ++k)
    if (std::abs(m[k]) > h[k] + aw[k]) return false;
  constexpr double kRound = 4.0 * std::numeric_limits<double>::epsilon();
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double mw = m[i] * w[j], wm = m[j] * w[i];
    if (std::abs(mw - wm) > h[i] * aw[j] + h[j] * aw[i] + kRound * (std::abs(mw) + std::abs(wm))) return false;
  }
  return true;
}

struct Ray {
  bool odd = false;         // parity of the transversal crossings
  bool degenerate = false;  // some triangle met degenerately: the parity means nothing
  bool on_surface = false;  // p is on a triangle
};

// The rays' directions after the first (classify_by_rays): a fixed pseudo-random sequence
// (SplitMix64: the same on every platform).
[[nodiscard]] Vec3 ray_direction(int attempt) {
  std::uint64_t state = 0x9e3779b97f4a7c15ull * static_cast<std::uint64_t>(attempt);
  const auto next = [&state] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53 * 2.0 - 1.0;  // [-1, 1)
  };
  for (;;) {
    const Vec3 d(next(), next(), next());
    const double n = d.norm();
    if (n > 0.25 && n <= 1.0) return d / n;
  }
}

// Gives up after this many degenerate rays (for a point off the surface the degenerate
// directions have measure zero: never observed beyond the second).
constexpr int kMaxRays = 64;

// Where the rays start and how far they must reach: beyond `extent` around `center` (the
// surface's bounding region, tree frame), measured from the point `pt` (tree frame).
[[nodiscard]] double ray_length(const Vec3& pt, const Vec3& center, const Vec3& half_extents) {
  const double length = 2.0 * ((pt - center).norm() + 2.0 * half_extents.norm());
  return length > 0.0 ? length : 1.0;
}

// The first ray's direction (query frame): of the six coordinate directions, the one that leaves
// `box` (tree frame, containing pt) soonest, so that the ray crosses as few nodes as it can.
// Any direction gives the same answer (a degenerate one is re-shot); this one is only cheaper.
[[nodiscard]] Vec3 shortest_exit(const Obb& box, const Pose* to_tree, const Vec3& pt) {
  const Vec3 local = box.to_local(pt);
  Vec3 best = Vec3::UnitX();
  double best_exit = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k)
    for (const double sign : {1.0, -1.0}) {
      const Vec3 d = sign * Vec3::Unit(k);
      // Without a pose, A^T d is sign times row k of A (the matrix product's other terms are
      // exact zeros), read rather than multiplied.
      const Vec3 along = to_tree != nullptr ? Vec3(box.axes.transpose() * (to_tree->rotation * d))
                                            : Vec3(sign * box.axes.row(k).transpose());
      double exit = std::numeric_limits<double>::infinity();
      for (int i = 0; i < 3; ++i) {
        if (along[i] == 0.0) continue;
        const double wall = along[i] > 0.0 ? box.half_extents[i] - local[i] : box.half_extents[i] + local[i];
        exit = std::min(exit, std::max(wall, 0.0) / std::abs(along[i]));
      }
      if (exit < best_exit) best_exit = exit, best = d;
    }
  return best;
}

// Classifies p (query frame) against a closed surface given as `triangles_met(p, q, pt, qt,
// ray)`, which adds the meetings of the segment pq (query frame; pt, qt the same in the tree
// frame) to `ray`. `to_tree` maps the query frame into the frame of the boxes (nullptr: the same).
// The first ray goes along `first` (a unit vector), the others along ray_direction().
template <class Cast>
[[nodiscard]] Containment classify_by_rays(const Vec3& p, const Pose* to_tree, const Vec3& center,
                                           const Vec3& half_extents, const Vec3& first, Cast&& cast) {
  const Vec3 pt = to_tree != nullptr ? to_tree->apply(p) : p;
  const double length = ray_length(pt, center, half_extents);
  for (int attempt = 0; attempt < kMaxRays; ++attempt) {
    const Vec3 q = p + length * (attempt == 0 ? first : ray_direction(attempt));
    if (q == p) continue;  // the length vanished against |p| (coordinates ~1e16 times the mesh)
    const Vec3 qt = to_tree != nullptr ? to_tree->apply(q) : q;
    Ray ray;
    cast(p, q, pt, qt, ray);
    if (ray.on_surface) return Containment::on_surface;
    if (!ray.degenerate) return ray.odd ? Containment::inside : Containment::outside;
  }
  throw std::runtime_error("classify_point: every ray met the surface degenerately");
}

// Adds the meeting of pq with one triangle to `ray`; false once p is found on the surface.
inline bool add_meeting(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, const Vec3& q, Ray& ray) {
  switch (meet(a, b, c, p, q)) {
    case Meet::cross: ray.odd = !ray.odd; break;
    case Meet::degenerate: ray.degenerate = true; break;  // keep walking: p may be on the surface
    case Meet::on_surface: ray.on_surface = true; return false;
    case Meet::miss: break;
  }
  return true;
}

// p (query frame) against the tree's mesh, whose corners in the query frame are corner(v).
template <class Corner>
[[nodiscard]] Containment classify_with_tree(const Tree& tree, const Mesh& mesh, const Corner& corner,
                                             const Pose* to_tree, const Vec3& p, std::vector<std::uint32_t>& stack) {
  if (tree.nodes.empty()) return Containment::outside;
  const Obb root = box_of(tree.nodes[0]);
  const Vec3 pt = to_tree != nullptr ? to_tree->apply(p) : p;
  // The slab test evaluates the float boxes' own definition (box_of): kBoxMargin for the transforms'
  // rounding suffices; kCompactBoxSlack (for tests that treat the axes as orthonormal) is not needed.
  const double margin = kBoxMargin * (query_detail::box_scale(tree.nodes[0].box) + pt.cwiseAbs().maxCoeff());
  // Outside the root box is outside the surface's hull (the common case for separated meshes).
  if (!root.contains(pt, margin)) return Containment::outside;
  return classify_by_rays(p, to_tree, root.center, root.half_extents, shortest_exit(root, to_tree, pt),
                          [&](const Vec3& p, const Vec3& q, const Vec3& pt, const Vec3& qt, Ray& ray) {
                            const double m = margin + kBoxMargin * qt.cwiseAbs().maxCoeff();
                            stack.clear();
                            stack.push_back(0);
                            while (!stack.empty()) {
                              const Node& node = tree.nodes[stack.back()];
                              stack.pop_back();
                              if (!segment_meets_box(box_of(node), pt, qt, m)) continue;
                              if (!node.is_leaf()) {
                                stack.push_back(node.first + 1);
                                stack.push_back(node.first);
                                continue;
                              }
                              for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                                const Triangle& t = mesh.triangles[tree.triangle_order[k]];
                                if (!add_meeting(corner(t[0]), corner(t[1]), corner(t[2]), p, q, ray)) return;
                              }
                            }
                          });
}

// The same over every triangle; the rays reach beyond the corners' bounding box.
template <class Corner>
[[nodiscard]] Containment classify_brute(const Mesh& mesh, const Corner& corner, const Vec3& p) {
  if (mesh.triangles.empty()) return Containment::outside;
  Vec3 lo = corner(mesh.triangles[0][0]), hi = lo;
  for (const Triangle& t : mesh.triangles)
    for (const std::uint32_t v : t) {
      const Vec3 c = corner(v);
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
  return classify_by_rays(p, nullptr, 0.5 * (lo + hi), 0.5 * (hi - lo), Vec3::UnitX(),
                          [&](const Vec3& p, const Vec3& q, const Vec3&, const Vec3&, Ray& ray) {
                            for (const Triangle& t : mesh.triangles)
                              if (!add_meeting(corner(t[0]), corner(t[1]), corner(t[2]), p, q, ray)) return;
                          });
}

}  // namespace

const char* to_string(Inside inside) {
  switch (inside) {
    case Inside::none: return "none";
    case Inside::b_in_a: return "b_in_a";
    case Inside::a_in_b: return "a_in_b";
  }
  return "?";
}

const char* to_string(Containment c) {
  switch (c) {
    case Containment::outside: return "outside";
    case Containment::inside: return "inside";
    case Containment::on_surface: return "on_surface";
  }
  return "?";
}

Containment classify_point(const Tree& tree, const Mesh& mesh, const Closedness& closedness, const Vec3& p) {
  require_closed(closedness, mesh, "classify_point", "");
  if (tree.triangle_order.size() != mesh.triangles.size())
    throw InputError("classify_point: the tree was built over " + std::to_string(tree.triangle_order.size()) +
                     " triangles but the mesh has " + std::to_string(mesh.triangles.size()));
  std::vector<std::uint32_t> stack;
  return classify_with_tree(
      tree, mesh, [&](std::uint32_t v) -> const Vec3& { return mesh.vertices[v]; }, nullptr, p, stack);
}

Containment classify_point_brute_force(const Mesh& mesh, const Closedness& closedness, const Vec3& p) {
  require_closed(closedness, mesh, "classify_point_brute_force", "");
  return classify_brute(mesh, [&](std::uint32_t v) -> const Vec3& { return mesh.vertices[v]; }, p);
}

namespace query_detail {

Containment classify_point_checked(const Tree& tree, const Mesh& mesh, const Vec3& p,
                                   std::vector<std::uint32_t>& stack) {
  return classify_with_tree(
      tree, mesh, [&](std::uint32_t v) -> const Vec3& { return mesh.vertices[v]; }, nullptr, p, stack);
}

// The first ray of classify_with_tree (along the coordinate axis of shortest_exit, over the same
// length) through the wide nodes. The segment pq, q = p + L d with d = s e_k, is the box of the
// kernel's A side: its ref the midpoint m = fl((p + q) / 2) (a double), axes the rows s e_k,
// e_(k+1), s e_(k+2) (exact, orthonormal, determinant 1: eta 0), center 0 and half extents
// (h, 0, 0) with h >= |p_k - m_k| and |q_k - m_k| rounded up to a float: p and q differ from m
// only in coordinate k, so the box contains the segment. Each node of B (the mesh's wide tree,
// frame the identity) is met with its ref's exact offset from m rounded by wide_pair, and the
// kernel's guarantee (wide_nodes.hpp: it never separates two boxes that share a point) keeps
// every child box the segment meets; leaves go through meet() as in classify_with_tree.
WideRays::WideRays(const Tree& tree, const WideTree& wide)
    : root(tree.nodes.empty() ? Obb{} : box_of(tree.nodes[0])),
      root_scale(tree.nodes.empty() ? 0.0 : box_scale(tree.nodes[0].box)),
      frame(wide_frame(Pose::identity(), 0.0, wide.eta, 0.0)) {}

Containment classify_point_wide(const Tree& tree, const WideTree& wide, const WideRays& rays, const Mesh& mesh,
                                const Vec3& p, std::vector<WideRayItem>& wide_stack,
                                std::vector<std::uint32_t>& stack) {
  if (tree.nodes.empty() || wide.nodes.empty()) return Containment::outside;
  const Obb& root = rays.root;
  const double margin = kBoxMargin * (rays.root_scale + p.cwiseAbs().maxCoeff());
  if (!root.contains(p, margin)) return Containment::outside;
  const Vec3 d = shortest_exit(root, nullptr, p);
  const Vec3 q = p + ray_length(p, root.center, root.half_extents) * d;
  int k = 0;
  while (d[k] == 0.0) ++k;
  const double sign = d[k];
  const auto corner = [&](std::uint32_t v) -> const Vec3& { return mesh.vertices[v]; };
  if (q == p || !q.allFinite()) return classify_with_tree(tree, mesh, corner, nullptr, p, stack);
  const Vec3 mid(k == 0 ? 0.5 * (p[0] + q[0]) : p[0], k == 1 ? 0.5 * (p[1] + q[1]) : p[1],
                 k == 2 ? 0.5 * (p[2] + q[2]) : p[2]);
  const double reach = std::max(std::abs(p[k] - mid[k]), std::abs(q[k] - mid[k])) * (1.0 + 0x1p-50);
  WideBox segment{};
  const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
  segment.axes[k] = static_cast<float>(sign);
  segment.axes[3 + k1] = 1.0f;
  segment.axes[6 + k2] = static_cast<float>(sign);
  segment.half[0] = std::nextafter(static_cast<float>(reach), std::numeric_limits<float>::infinity());
  const WideFrame& frame = rays.frame;
  // hoist() of the segment for each node (hoist_identity), its M computed once.
  const WideHoisted hoisted = hoist(frame, WidePair{{0.0f, 0.0f, 0.0f}, 0.0f}, segment);
  // Its M: row i is the segment's axis i, s e_k, e_(k+1), s e_(k+2) (the frame is the identity).
  const WidePermutation perm{{k, k1, k2}, {static_cast<float>(sign), 1.0f, static_cast<float>(sign)}};
  const auto place = [&](const Vec3& ref) { return hoist_identity(frame, hoisted, segment, mid, ref); };
  Ray ray;
  // The kept children of a node: internal ones onto the stack, leaves' triangles met. False once
  // p is found on the surface.
  const auto visit = [&](const WideRayItem& item, const WideNode& node, unsigned kept) {
    for (; kept != 0; kept &= kept - 1) {
      const int lane = std::countr_zero(kept);
      const std::int32_t child = node.child[lane];
      if (child > 0) {
        wide_stack.push_back({child, child_ref(item.ref, node, lane)});
        continue;
      }
      const WideTree::LeafRange leaf = wide.leaf(child);
      for (std::uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i) {
        const Triangle& t = mesh.triangles[tree.triangle_order[i]];
        if (!add_meeting(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]], p, q, ray)) return false;
      }
    }
    return true;
  };
  // Two nodes a kernel call where the CPU has AVX2 (wide_overlap2: the same lanes' decisions),
  // taken in the order they were found (a queue: the nodes a ray meets at one depth wait
  // together, so that there are two to pair more often than on a stack; parity does not depend
  // on the order).
  const bool avx2 = avx2_bounds_available();
  wide_stack.clear();
  wide_stack.push_back({0, wide.root_ref});
  for (std::size_t next = 0; next < wide_stack.size();) {
    const WideRayItem x = wide_stack[next++];
    const WideNode& nx = wide.nodes[static_cast<std::size_t>(x.node)];
    if (next == wide_stack.size()) {
      if (!visit(x, nx, wide_overlap_permuted(place(x.ref), perm, nx))) return Containment::on_surface;
      continue;
    }
    const WideRayItem y = wide_stack[next++];
    const WideNode& ny = wide.nodes[static_cast<std::size_t>(y.node)];
    const unsigned both = wide_overlap2_permuted(place(x.ref), nx, place(y.ref), ny, perm, avx2);
    if (!visit(x, nx, both & 0xFu) || !visit(y, ny, both >> 4)) return Containment::on_surface;
  }
  if (ray.on_surface) return Containment::on_surface;
  if (!ray.degenerate) return ray.odd ? Containment::inside : Containment::outside;
  return classify_with_tree(tree, mesh, corner, nullptr, p, stack);
}

SolidMeshes::SolidMeshes(const char* query, const Mesh& ma, const Closedness* given_a, const Mesh& mb,
                         const Closedness* given_b) {
  if (given_a == nullptr) given_a = &own_a_.emplace(check_closed(ma));
  if (given_b == nullptr) given_b = &own_b_.emplace(check_closed(mb));
  require_closed(*given_a, ma, query, "A");
  require_closed(*given_b, mb, query, "B");
  a_ = given_a;
  b_ = given_b;
}

SolidHit SolidMeshes::overlap(const Tree& ta, const Mesh& ma, const Tree& tb, const Mesh& mb, const Pose& rel) const {
  std::vector<std::uint32_t> stack;
  stack.reserve(64);
  const auto corner_a = [&](std::uint32_t v) -> const Vec3& { return ma.vertices[v]; };
  for (const std::uint32_t v : b_->pieces) {
    const Vec3 p = map_point(rel, mb.vertices[v]);
    if (classify_with_tree(ta, ma, corner_a, nullptr, p, stack) != Containment::outside)
      return {Inside::b_in_a, p, mb.vertices[v]};
  }
  // A's vertex against B's triangles mapped into A's frame (the triangles every other test of
  // the query sees); B's boxes are tested in B's frame with the segment mapped back.
  const Pose to_b = rel.inverse();
  const auto corner_b = [&](std::uint32_t v) { return map_point(rel, mb.vertices[v]); };
  for (const std::uint32_t v : a_->pieces) {
    const Vec3& p = ma.vertices[v];
    if (classify_with_tree(tb, mb, corner_b, &to_b, p, stack) != Containment::outside)
      return {Inside::a_in_b, p, to_b.apply(p)};
  }
  return {};
}

SolidHit SolidMeshes::overlap_brute_force(const Mesh& ma, const Mesh& mb, const Pose& rel) const {
  const auto corner_a = [&](std::uint32_t v) -> const Vec3& { return ma.vertices[v]; };
  for (const std::uint32_t v : b_->pieces) {
    const Vec3 p = map_point(rel, mb.vertices[v]);
    if (classify_brute(ma, corner_a, p) != Containment::outside) return {Inside::b_in_a, p, mb.vertices[v]};
  }
  const auto corner_b = [&](std::uint32_t v) { return map_point(rel, mb.vertices[v]); };
  for (const std::uint32_t v : a_->pieces) {
    const Vec3& p = ma.vertices[v];
    if (classify_brute(mb, corner_b, p) != Containment::outside) return {Inside::a_in_b, p, rel.inverse().apply(p)};
  }
  return {};
}

}  // namespace query_detail
}  // namespace tightbvh
