

// 3D convex hull by Quickhull (Barber, Dobkin & Huhdanpaa 1996, "The Quickhull algorithm for
// convex hulls", ACM TOMS 22(4)) with exact orientation predicates; 2D hull by Andrew's
// monotone chain.
//
// Robustness: a point is above a face only when orient3d is strictly positive, evaluated
// exactly (src/geometry/predicates.hpp). The hull under construction is then always convex in exact
// arithmetic, the faces a point sees form a disk whose boundary (the horizon) is a simple cycle,
// and the new faces of the cone are never degenerate. Floating point only ranks the outside
// points of a face (to pick the farthest) and gives the face normals.
#include "tightbvh/hull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "predicates.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {

void ConvexHull3::clear() {
  dimension = 0;
  vertices.clear();
  input_index.clear();
  faces.clear();
  face_normals.clear();
  edges.clear();
  neighbor_offsets.clear();
  neighbors.clear();
  plane_normal = Vec3::UnitZ();
}

namespace quickhull {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// A point waiting in an outside set, with its coordinates: the partition loops read these
// buffers front to back instead of gathering points by index.
struct OutsidePoint {
  Vec3 p;
  std::uint32_t id;
};

// A triangle of the hull under construction: counter-clockwise seen from outside;
// adjacent[k] is the face across the edge (vertex[k + 1], vertex[k + 2]).
struct Face {
  std::array<std::uint32_t, 3> vertex;
  std::array<std::uint32_t, 3> adjacent{kNone, kNone, kNone};
  detail::OrientPlane plane;  // sign(p) > 0: p strictly above (outside)
  // The outside set: State::pool[outside_begin, outside_begin + outside_size).
  std::uint32_t outside_begin = 0;
  std::uint32_t outside_size = 0;
  std::uint32_t farthest = kNone;  // the point picked from the outside set
  double farthest_value = 0.0;     // its rounded plane.normal . (p - a)
  // Equal ids: exactly coplanar faces (found when a face is made next to a coplanar one). Lets a
  // point that is exactly on one such face skip the costly exact test against the others.
  std::uint32_t plane_id = kNone;
  std::uint32_t stamp = 0;  // the iteration that last computed `apex_side`
  int apex_side = 0;        // sign of that iteration's apex against this face
  bool alive = true;

  Face(std::span<const Vec3> points, std::uint32_t a, std::uint32_t b, std::uint32_t c)
      : vertex{a, b, c}, plane(points[a], points[b], points[c]) {}
};

// An edge of the horizon, oriented as in the visible face it bounds; `outer` is the face
// across it that stays.
struct HorizonEdge {
  std::uint32_t from, to, outer;
};

}  // namespace quickhull

struct HullWorkspace::State {
  // Quickhull
  std::vector<quickhull::Face> faces;
  std::vector<std::uint32_t> free_faces;  // slots of deleted faces, reused
  // Faces with outside points, a max-heap by the distance of their farthest point (a face may
  // appear again after it was processed or replaced: such entries are skipped).
  std::vector<std::pair<double, std::uint32_t>> pending;
  std::vector<std::uint32_t> candidates;  // the points the hull is built from
  std::vector<quickhull::OutsidePoint> pool, spare_pool;  // the outside sets, and a compaction buffer
  std::vector<quickhull::OutsidePoint> unassigned;        // points being partitioned
  std::vector<std::uint32_t> on_plane;    // by point: plane_id of a face it is exactly on
  std::vector<std::uint32_t> visible;
  std::vector<std::uint32_t> search;
  std::vector<quickhull::HorizonEdge> horizon;
  std::vector<std::uint32_t> horizon_from;  // by point: the horizon edge leaving it
  std::vector<std::uint32_t> cycle;         // horizon edges in order
  std::vector<std::uint32_t> new_faces;
  // Removal of vertices that are not strictly extreme
  std::vector<std::uint32_t> corner_face;  // by point: a live face with that vertex
  std::vector<std::uint32_t> sharp;        // by point: incident edges between faces on two planes
  std::vector<std::uint32_t> doomed;       // vertices to remove
  std::vector<std::uint32_t> fan, link;    // faces around the vertex, their far vertices in order
  std::vector<std::uint32_t> polygon;      // one planar polygon to triangulate
  std::vector<std::array<std::uint32_t, 2>> open_edges;  // directed edge -> (face, slot) to match
  std::vector<std::uint32_t> open_faces;
  // Conversion to ConvexHull3
  std::vector<std::uint32_t> vertex_of;    // by point: output vertex, kNone when not one
  std::vector<std::uint32_t> face_index;   // by face slot: output face
  std::vector<std::uint32_t> group;        // by face slot: union-find of coplanar faces
  std::vector<std::uint32_t> group_best;   // by root: its face with the longest rounded normal
  std::vector<Vec3> group_normal;          // by root: the unit normal of that face
  std::vector<std::uint32_t> sharp_edges;  // by output vertex: incident edges between two planes
  std::vector<std::uint32_t> degree;
  // Planar sets
  std::vector<Vec2> plane_points;
  std::vector<std::uint32_t> plane_ids;
};

HullWorkspace::HullWorkspace() : state_(std::make_unique<State>()) {}
HullWorkspace::~HullWorkspace() = default;
HullWorkspace::HullWorkspace(HullWorkspace&&) noexcept = default;
HullWorkspace& HullWorkspace::operator=(HullWorkspace&&) noexcept = default;

namespace {

using quickhull::Face;
using quickhull::kNone;
using quickhull::OutsidePoint;
using State = HullWorkspace::State;

// Quickhull of points[s.candidates] from an exactly non-degenerate tetrahedron (Barber et al.
// 1996): every outside point belongs to the outside set of one face it is strictly
// above; repeatedly take a face's farthest outside point, delete the faces it sees, cone it to
// the horizon and re-partition the deleted faces' outside sets among the new faces. A point
// above none of them is inside or on the new hull and is dropped for good.
class Quickhull {
 public:
  // `extent`: the extents of a box holding all the points.
  Quickhull(std::span<const Vec3> points, const Vec3& extent, State& s) : p_(points), s_(s), extent_(extent) {}

  // The farthest-point picks can leave a vertex inside a flat facet or inside an edge of the
  // hull (ties on coplanar and collinear sets). Removes those vertices by triangulating the
  // planar polygon(s) around each (their links); false when that fails (never expected).
  bool remove_non_extreme_vertices() {
    if (s_.corner_face.size() < p_.size()) {
      s_.corner_face.resize(p_.size());
      s_.sharp.resize(p_.size(), 0);
    }
    s_.doomed.clear();
    for (std::uint32_t f = 0; f < s_.faces.size(); ++f)
      if (s_.faces[f].alive)
        for (std::uint32_t v : s_.faces[f].vertex) s_.corner_face[v] = f, s_.sharp[v] = 0;
    for (std::uint32_t f = 0; f < s_.faces.size(); ++f) {
      const Face& face = s_.faces[f];
      if (!face.alive) continue;
      for (std::uint32_t k = 0; k < 3; ++k)
        if (face.adjacent[k] > f && !coplanar(f, face.adjacent[k]))
          ++s_.sharp[face.vertex[(k + 1) % 3]], ++s_.sharp[face.vertex[(k + 2) % 3]];
    }
    for (std::uint32_t f = 0; f < s_.faces.size(); ++f) {
      if (!s_.faces[f].alive) continue;
      for (std::uint32_t v : s_.faces[f].vertex)
        if (s_.sharp[v] < 3 && s_.corner_face[v] == f) s_.doomed.push_back(v);  // once per vertex
    }
    // Removing a vertex keeps the other vertices' sharp edge counts (see remove_vertex).
    for (std::uint32_t v : s_.doomed)
      if (!remove_vertex(v)) return false;
    return true;
  }

  void run(const std::array<std::uint32_t, 4>& simplex) {
    s_.faces.clear();
    s_.free_faces.clear();
    s_.pending.clear();
    s_.pool.clear();
    live_ = 0;
    if (s_.on_plane.size() < p_.size()) {
      s_.on_plane.resize(p_.size());
      s_.horizon_from.resize(p_.size());
    }
    start(simplex);
    std::uint32_t stamp = 0;
    // Every iteration makes one more point a vertex: at most one per candidate.
    std::size_t iterations = 0;
    // The farthest outside point of all first: fewer vertices are added and swallowed again
    // than in depth-first order (man.off: 513 points added for 480 vertices, against 1193).
    while (!s_.pending.empty()) {
      std::pop_heap(s_.pending.begin(), s_.pending.end());
      const std::uint32_t f = s_.pending.back().second;
      s_.pending.pop_back();
      if (!s_.faces[f].alive || s_.faces[f].outside_size == 0) continue;
      if (++iterations > s_.candidates.size())
        throw InputError("convex_hull: no progress (coordinates too large: overflow?)");
      add_point(f, s_.faces[f].farthest, ++stamp);
    }
  }

 private:
  std::span<const Vec3> p_;
  State& s_;
  Vec3 extent_;
  std::uint32_t next_plane_id_ = 0;
  std::size_t live_ = 0;  // points in outside sets of live faces

  std::uint32_t new_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (!s_.free_faces.empty()) {
      const std::uint32_t f = s_.free_faces.back();
      s_.free_faces.pop_back();
      s_.faces[f] = Face(p_, a, b, c);
      return f;
    }
    s_.faces.emplace_back(p_, a, b, c);
    return static_cast<std::uint32_t>(s_.faces.size() - 1);
  }

  // Faces f and g (neighbours) lie in one plane, exactly.
  bool coplanar(std::uint32_t f, std::uint32_t g) const {
    const Face &a = s_.faces[f], &b = s_.faces[g];
    if (a.plane_id == b.plane_id) return true;
    for (std::uint32_t k = 0; k < 3; ++k)
      if (b.adjacent[k] == f) return a.plane.sign(p_[b.vertex[k]]) == 0;
    return false;
  }

  // Removes vertex v, which has fewer than three sharp edges (between faces on two planes).
  // With none, v lies inside a flat facet: its link is a planar polygon, triangulated anew.
  // With two, both lie on the line where the two planes meet and v inside the edge between its
  // two neighbours u, w on that line: the link splits into one polygon per plane, each closed
  // by the new edge u-w (sharp, so u's and w's counts stay). The new faces keep the plane ids.
  bool remove_vertex(std::uint32_t v) {
    // The fan around v, counter-clockwise seen from outside: fan[i] = (v, link[i], link[i + 1]).
    s_.fan.clear();
    s_.link.clear();
    std::uint32_t f = s_.corner_face[v];
    do {
      const Face& face = s_.faces[f];
      const std::uint32_t k = face.vertex[0] == v ? 0 : face.vertex[1] == v ? 1 : 2;
      s_.fan.push_back(f);
      s_.link.push_back(face.vertex[(k + 1) % 3]);
      f = face.adjacent[(k + 1) % 3];  // across (link[i + 1], v)
      if (s_.fan.size() > s_.faces.size()) return false;
    } while (f != s_.fan[0]);
    const std::size_t m = s_.fan.size();
    // Sharp edges (v, link[i]) between fan[i - 1] and fan[i].
    std::uint32_t sharp_at[2] = {0, 0};
    int sharp_count = 0;
    for (std::size_t i = 0; i < m; ++i)
      if (!coplanar(s_.fan[(i + m - 1) % m], s_.fan[i])) {
        if (sharp_count == 2) return false;
        sharp_at[sharp_count++] = static_cast<std::uint32_t>(i);
      }
    if (sharp_count == 1) return false;
    s_.open_edges.clear();
    s_.open_faces.clear();
    if (sharp_count == 0) {
      s_.polygon.assign(s_.link.begin(), s_.link.end());
      if (!triangulate(s_.fan[0])) return false;
    } else {
      for (int half = 0; half < 2; ++half) {
        const std::uint32_t from = sharp_at[half], to = sharp_at[1 - half];
        s_.polygon.clear();
        for (std::uint32_t i = from; i != to; i = static_cast<std::uint32_t>((i + 1) % m)) s_.polygon.push_back(s_.link[i]);
        s_.polygon.push_back(s_.link[to]);
        if (!triangulate(s_.fan[from])) return false;
      }
    }
    // Link the new faces: to the outer faces across the old link edges, and to each other.
    for (std::size_t i = 0; i < m; ++i) {
      const Face& old = s_.faces[s_.fan[i]];
      const std::uint32_t k = old.vertex[0] == v ? 0 : old.vertex[1] == v ? 1 : 2;
      const std::uint32_t outer = old.adjacent[k];
      const std::uint32_t a = s_.link[i], b = s_.link[(i + 1) % m];
      if (!attach(a, b, outer)) return false;
    }
    for (std::size_t i = 0; i < s_.open_edges.size(); ++i) {
      const auto [face, slot] = s_.open_edges[i];
      if (s_.faces[face].adjacent[slot] != kNone) continue;
      const Face& mine = s_.faces[face];
      const std::uint32_t a = mine.vertex[(slot + 1) % 3], b = mine.vertex[(slot + 2) % 3];
      bool found = false;
      for (std::uint32_t g : s_.open_faces) {
        const std::uint32_t other = slot_of_edge(s_.faces[g], b, a);
        if (g == face || other == kNone) continue;
        s_.faces[face].adjacent[slot] = g;
        s_.faces[g].adjacent[other] = face;
        found = true;
        break;
      }
      if (!found) return false;
    }
    for (std::uint32_t old : s_.fan) {
      s_.faces[old].alive = false;
      s_.free_faces.push_back(old);
    }
    return true;
  }

  // The new face holding directed edge a -> b takes `outer` as its neighbour there.
  bool attach(std::uint32_t a, std::uint32_t b, std::uint32_t outer) {
    for (std::uint32_t g : s_.open_faces) {
      const std::uint32_t k = slot_of_edge(s_.faces[g], a, b);
      if (k == kNone) continue;
      s_.faces[g].adjacent[k] = outer;
      Face& o = s_.faces[outer];
      const std::uint32_t back = slot_of_edge(o, b, a);
      if (back == kNone) return false;
      o.adjacent[back] = g;
      return true;
    }
    return false;
  }

  // Ear clipping of s.polygon (counter-clockwise seen from outside, in the plane of face
  // `plane_face`), with exact orientations in the projection that drops the plane normal's
  // largest coordinate. New faces go to s.open_faces with all three edges open.
  bool triangulate(std::uint32_t plane_face) {
    const Face& reference = s_.faces[plane_face];
    const std::uint32_t plane_id = reference.plane_id;
    // Drop the largest coordinate of the rounded normal, or, if the reference face projects to a
    // segment exactly there (a sliver, whose rounded normal can be zero), one where it does not:
    // a triangle that is not degenerate has a non-degenerate projection on some coordinate plane.
    int drop = 0;
    reference.plane.normal.cwiseAbs().maxCoeff(&drop);
    int x = 0, y = 0, flip = 0;
    const auto orient = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      const Vec3 &pa = p_[a], &pb = p_[b], &pc = p_[c];
      return detail::orient2d(pa[x], pa[y], pb[x], pb[y], pc[x], pc[y]);
    };
    for (int attempt = 0; attempt < 3 && flip == 0; ++attempt) {
      x = (drop + attempt + 1) % 3, y = (drop + attempt + 2) % 3;
      // The projection's orientation against the true one, from the reference face itself.
      flip = orient(reference.vertex[0], reference.vertex[1], reference.vertex[2]);
    }
    if (flip == 0) return false;
    auto& poly = s_.polygon;
    while (poly.size() > 3) {
      const std::size_t n = poly.size();
      std::size_t ear = n;
      for (std::size_t i = 0; i < n && ear == n; ++i) {
        const std::uint32_t a = poly[(i + n - 1) % n], b = poly[i], c = poly[(i + 1) % n];
        if (orient(a, b, c) * flip <= 0) continue;  // reflex or flat corner
        bool empty = true;
        for (std::size_t j = 0; j < n && empty; ++j) {
          const std::uint32_t q = poly[j];
          if (q == a || q == b || q == c) continue;
          empty = !(orient(a, b, q) * flip >= 0 && orient(b, c, q) * flip >= 0 && orient(c, a, q) * flip >= 0);
        }
        if (empty) ear = i;
      }
      if (ear == n) return false;
      add_triangle(poly[(ear + n - 1) % n], poly[ear], poly[(ear + 1) % n], plane_id);
      poly.erase(poly.begin() + static_cast<std::ptrdiff_t>(ear));
    }
    if (orient(poly[0], poly[1], poly[2]) * flip <= 0) return false;
    add_triangle(poly[0], poly[1], poly[2], plane_id);
    return true;
  }

  void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t plane_id) {
    const std::uint32_t f = new_face(a, b, c);
    s_.faces[f].plane_id = plane_id;
    s_.open_faces.push_back(f);
    for (std::uint32_t k = 0; k < 3; ++k) s_.open_edges.push_back({f, k});
    for (std::uint32_t v : {a, b, c}) s_.corner_face[v] = f;
  }

  // Ranks outside points: by distance, and among (nearly) equally far ones the lexicographically
  // largest, which is a vertex of their hull: ties along a line or plane parallel to the face
  // (ruled and flat CAD surfaces) then pick an end point, not one that later lies on an edge.
  static constexpr double kTie = 1e-12;
  static bool farther(const Vec3& a, double a_value, const Vec3& b, double b_value) {
    if (a_value > b_value * (1 + kTie)) return true;
    if (a_value < b_value * (1 - kTie)) return false;
    return a.x() > b.x() || (a.x() == b.x() && (a.y() > b.y() || (a.y() == b.y() && a.z() > b.z())));
  }

  // Moves the points of s.unassigned that are strictly above face f into f's outside set (at
  // the end of the pool) and keeps the others in s.unassigned, in order.
  void claim(std::uint32_t f) {
    Face& face = s_.faces[f];
    const detail::OrientPlane plane = face.plane;  // a local copy: the loop's stores cannot alias it
    const std::uint32_t plane_id = face.plane_id;
    // The rounded determinant decides most points against one bound for the whole set.
    const double bound = plane.bound_within(extent_);
    const std::size_t begin = s_.pool.size();
    s_.pool.reserve(begin + s_.unassigned.size());
    std::size_t kept = 0;
    std::uint32_t best = kNone;
    double best_value = 0.0, tie_value = 0.0;
    Vec3 best_point = Vec3::Zero();
    for (const OutsidePoint& q : s_.unassigned) {
      double value;
      bool above, below;
      plane.classify_within(q.p, bound, value, above, below);
      if (!above && !below) [[unlikely]] {
        int side = plane.filter(q.p, value);
        if (side == detail::kUndecided) {
          if (s_.on_plane[q.id] == plane_id) {
            side = 0;
          } else {
            side = plane.resolve(q.p);
            if (side == 0) s_.on_plane[q.id] = plane_id;
          }
        }
        above = side > 0;
      }
      if (!above) {
        s_.unassigned[kept++] = q;
        continue;
      }
      s_.pool.push_back(q);
      // (An exactly positive point can have a rounded determinant <= 0: never compare to 0.)
      if (best == kNone || (value >= tie_value && farther(q.p, value, best_point, best_value))) {
        best = q.id, best_value = value, best_point = q.p;
        tie_value = value - std::abs(value) * kTie;
      }
    }
    s_.unassigned.resize(kept);
    face.outside_begin = static_cast<std::uint32_t>(begin);
    face.outside_size = static_cast<std::uint32_t>(s_.pool.size() - begin);
    face.farthest = best;
    face.farthest_value = best_value;
    live_ += face.outside_size;
    if (face.outside_size > 0) {
      // A sliver's rounded normal can be zero: rank its points last rather than by 0 / 0.
      const double norm = plane.normal.norm();
      s_.pending.emplace_back(norm > 0.0 ? best_value / norm : 0.0, f);
      std::push_heap(s_.pending.begin(), s_.pending.end());
    }
  }

  // The pool only grows while faces die; moves the live outside sets to the front once three
  // quarters of it are dead (at half, compaction took 5% of man.off's hull).
  void compact_pool() {
    if (s_.pool.size() < 4096 || s_.pool.size() < 4 * live_) return;
    s_.spare_pool.clear();
    for (Face& face : s_.faces) {
      if (!face.alive || face.outside_size == 0) continue;
      const auto begin = s_.pool.begin() + face.outside_begin;
      face.outside_begin = static_cast<std::uint32_t>(s_.spare_pool.size());
      s_.spare_pool.insert(s_.spare_pool.end(), begin, begin + face.outside_size);
    }
    s_.pool.assign(s_.spare_pool.begin(), s_.spare_pool.end());  // (a swap would trade capacities)
  }

  // The slot of `face` whose edge runs from -> to (kNone when it has no such edge).
  static std::uint32_t slot_of_edge(const Face& face, std::uint32_t from, std::uint32_t to) {
    for (std::uint32_t k = 0; k < 3; ++k)
      if (face.vertex[(k + 1) % 3] == from && face.vertex[(k + 2) % 3] == to) return k;
    return kNone;
  }

  void start(std::array<std::uint32_t, 4> t) {
    // Orient so that t[3] is below the plane of (t[0], t[1], t[2]); then these four faces are
    // counter-clockwise seen from outside.
    if (detail::orient3d(p_[t[0]], p_[t[1]], p_[t[2]], p_[t[3]]) > 0) std::swap(t[1], t[2]);
    next_plane_id_ = 0;
    const std::uint32_t f[4] = {new_face(t[0], t[1], t[2]), new_face(t[0], t[3], t[1]), new_face(t[1], t[3], t[2]),
                                new_face(t[2], t[3], t[0])};
    for (std::uint32_t i : f) s_.faces[i].plane_id = next_plane_id_++;
    for (std::uint32_t i : f)
      for (std::uint32_t k = 0; k < 3; ++k) {
        Face& face = s_.faces[i];
        for (std::uint32_t j : f)
          if (j != i && slot_of_edge(s_.faces[j], face.vertex[(k + 2) % 3], face.vertex[(k + 1) % 3]) != kNone)
            face.adjacent[k] = j;
      }
    s_.unassigned.clear();
    for (std::uint32_t q : s_.candidates) {
      s_.on_plane[q] = kNone;
      if (q != t[0] && q != t[1] && q != t[2] && q != t[3]) s_.unassigned.push_back({p_[q], q});
    }
    for (std::uint32_t i : f) claim(i);
  }

  // The faces `apex` sees (strictly), found by a search from `seed` over face adjacency, and
  // the horizon edges around them.
  void find_visible(std::uint32_t seed, std::uint32_t apex, std::uint32_t stamp) {
    s_.visible.clear();
    s_.horizon.clear();
    s_.search.clear();
    Face& first = s_.faces[seed];
    first.stamp = stamp;
    first.apex_side = 1;
    s_.visible.push_back(seed);
    s_.search.push_back(seed);
    while (!s_.search.empty()) {
      const std::uint32_t f = s_.search.back();
      s_.search.pop_back();
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t g = s_.faces[f].adjacent[k];
        Face& other = s_.faces[g];
        if (other.stamp != stamp) {
          other.stamp = stamp;
          other.apex_side = other.plane_id == s_.on_plane[apex] ? 0 : other.plane.sign(p_[apex]);
          if (other.apex_side > 0) {
            s_.visible.push_back(g);
            s_.search.push_back(g);
          }
        }
        if (other.apex_side <= 0)
          s_.horizon.push_back({s_.faces[f].vertex[(k + 1) % 3], s_.faces[f].vertex[(k + 2) % 3], g});
      }
    }
  }

  // Orders the horizon edges into their cycle (s.cycle).
  void order_horizon() {
    const std::size_t n = s_.horizon.size();
    for (std::size_t i = 0; i < n; ++i) s_.horizon_from[s_.horizon[i].from] = static_cast<std::uint32_t>(i);
    s_.cycle.clear();
    std::uint32_t e = 0;
    for (std::size_t i = 0; i < n; ++i) {
      s_.cycle.push_back(e);
      const std::uint32_t next = s_.horizon_from[s_.horizon[e].to];
      // Exact predicates make the horizon a simple cycle; anything else means bad coordinates.
      if (next >= n || s_.horizon[next].from != s_.horizon[e].to || (next == 0) != (i + 1 == n))
        throw InputError("convex_hull: inconsistent horizon (coordinates too large: overflow?)");
      e = next;
    }
  }

  void add_point(std::uint32_t seed, std::uint32_t apex, std::uint32_t stamp) {
    find_visible(seed, apex, stamp);
    order_horizon();
    // The cone from the apex to the horizon: new face i = (from_i, to_i, apex).
    const std::size_t n = s_.cycle.size();
    s_.new_faces.clear();
    for (std::uint32_t e : s_.cycle) {
      const quickhull::HorizonEdge edge = s_.horizon[e];
      const std::uint32_t f = new_face(edge.from, edge.to, apex);
      s_.new_faces.push_back(f);
      Face& outer = s_.faces[edge.outer];
      outer.adjacent[slot_of_edge(outer, edge.to, edge.from)] = f;
      Face& face = s_.faces[f];
      face.adjacent[2] = edge.outer;
      // The apex on the outer face's plane: the new face lies in that plane too.
      if (outer.apex_side == 0) face.plane_id = outer.plane_id;
    }
    for (std::size_t i = 0; i < n; ++i) {
      Face& face = s_.faces[s_.new_faces[i]];
      face.adjacent[0] = s_.new_faces[(i + 1) % n];      // across (to, apex)
      face.adjacent[1] = s_.new_faces[(i + n - 1) % n];  // across (apex, from)
      if (face.plane_id != kNone) continue;
      // A new plane, unless the previous cone face is coplanar (collinear horizon edges).
      const Face& previous = s_.faces[s_.new_faces[(i + n - 1) % n]];
      face.plane_id = i > 0 && previous.plane.sign(p_[face.vertex[1]]) == 0 ? previous.plane_id : next_plane_id_++;
    }
    // Re-partition the outside sets of the deleted faces (Barber et al.'s partition step).
    s_.unassigned.clear();
    for (std::uint32_t v : s_.visible) {
      Face& dead = s_.faces[v];
      for (std::uint32_t i = dead.outside_begin; i < dead.outside_begin + dead.outside_size; ++i)
        if (s_.pool[i].id != apex) s_.unassigned.push_back(s_.pool[i]);
      live_ -= dead.outside_size;
      dead.alive = false;
      dead.outside_size = 0;
      s_.free_faces.push_back(v);
    }
    for (std::uint32_t f : s_.new_faces) {
      if (s_.unassigned.empty()) break;
      claim(f);
    }
    compact_pool();
  }
};

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// The vertex of `face` that is not on its edge shared with face `other`.
std::uint32_t vertex_opposite(const Face& face, std::uint32_t other) {
  for (std::uint32_t k = 0; k < 3; ++k)
    if (face.adjacent[k] == other) return face.vertex[k];
  return face.vertex[0];
}

// Converts the quickhull faces into `out` (vertices in input order, faces, edges, one normal
// per coplanar group). Returns false when some vertex is not strictly extreme: a vertex is a
// corner of the polytope iff at least three of its edges join faces on different planes (with
// none it lies inside a flat facet; with two, both edges lie on the line where the two planes
// meet, so it lies inside an edge).
bool convert(std::span<const Vec3> points, State& s, ConvexHull3& out) {
  const std::size_t slots = s.faces.size();
  if (s.vertex_of.size() < points.size()) s.vertex_of.resize(points.size(), kNone);
  out.vertices.clear();
  out.input_index.clear();
  out.faces.clear();
  out.face_normals.clear();
  out.edges.clear();
  s.face_index.assign(slots, kNone);
  for (std::uint32_t f = 0; f < slots; ++f) {
    const Face& face = s.faces[f];
    if (!face.alive) continue;
    s.face_index[f] = static_cast<std::uint32_t>(out.faces.size());
    out.faces.push_back(face.vertex);  // point ids for now
    for (std::uint32_t v : face.vertex)
      if (s.vertex_of[v] == kNone) s.vertex_of[v] = 0, out.input_index.push_back(v);
  }
  std::sort(out.input_index.begin(), out.input_index.end());
  for (std::size_t i = 0; i < out.input_index.size(); ++i) {
    s.vertex_of[out.input_index[i]] = static_cast<std::uint32_t>(i);
    out.vertices.push_back(points[out.input_index[i]]);
  }
  for (auto& face : out.faces)
    for (std::uint32_t& v : face) v = s.vertex_of[v];
  for (std::uint32_t id : out.input_index) s.vertex_of[id] = kNone;  // clean for the next call

  // Edges; coplanar neighbours (exactly) join one group.
  s.group.resize(slots);
  for (std::uint32_t f = 0; f < slots; ++f) s.group[f] = f;
  s.sharp_edges.assign(out.vertices.size(), 0);
  for (std::uint32_t f = 0; f < slots; ++f) {
    const Face& face = s.faces[f];
    if (!face.alive) continue;
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t g = face.adjacent[k];
      if (g < f) continue;
      const std::uint32_t fi = s.face_index[f], gi = s.face_index[g];
      HullEdge e;
      e.vertex = {out.faces[fi][(k + 1) % 3], out.faces[fi][(k + 2) % 3]};
      e.face = {fi, gi};
      out.edges.push_back(e);
      if (face.plane_id == s.faces[g].plane_id || face.plane.sign(points[vertex_opposite(s.faces[g], f)]) == 0) {
        s.group[find_root(s.group, f)] = find_root(s.group, g);
      } else {
        ++s.sharp_edges[e.vertex[0]];
        ++s.sharp_edges[e.vertex[1]];
      }
    }
  }
  bool all_extreme = true;
  for (std::uint32_t count : s.sharp_edges) all_extreme = all_extreme && count >= 3;
  if (!all_extreme) return false;

  // One normal per group, from its best-conditioned triangle (the longest rounded cross product).
  s.group_best.assign(slots, kNone);
  for (std::uint32_t f = 0; f < slots; ++f) {
    if (!s.faces[f].alive) continue;
    std::uint32_t& best = s.group_best[find_root(s.group, f)];
    if (best == kNone || s.faces[f].plane.normal.squaredNorm() > s.faces[best].plane.normal.squaredNorm()) best = f;
  }
  // Its normal from the accurate cross product: a group that is a single sliver has a rounded
  // normal that is noise or zero.
  s.group_normal.resize(slots);
  for (std::uint32_t f = 0; f < slots; ++f) {
    if (!s.faces[f].alive || s.group_best[f] == kNone) continue;
    const auto& v = s.faces[s.group_best[f]].vertex;
    s.group_normal[f] = detail::accurate_normal(points[v[0]], points[v[1]], points[v[2]]).normalized();
  }
  for (std::uint32_t f = 0; f < slots; ++f)
    if (s.faces[f].alive) out.face_normals.push_back(s.group_normal[find_root(s.group, f)]);
  return true;
}

// The strictly extreme vertices of a hull that convert() rejected, as the next candidates.
void keep_extreme_vertices(const ConvexHull3& out, State& s) {
  s.candidates.clear();
  for (std::size_t v = 0; v < out.vertices.size(); ++v)
    if (s.sharp_edges[v] >= 3) s.candidates.push_back(out.input_index[v]);
}

bool collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  return detail::orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()) == 0 &&
         detail::orient2d(a.y(), a.z(), b.y(), b.z(), c.y(), c.z()) == 0 &&
         detail::orient2d(a.z(), a.x(), b.z(), b.x(), c.z(), c.x()) == 0;
}

// Four candidates spanning a tetrahedron (exactly): the first point, the first different one,
// the first not on their line, the first not on their plane. False when there are none.
bool exact_simplex(std::span<const Vec3> points, std::span<const std::uint32_t> ids,
                   std::array<std::uint32_t, 4>& t) {
  std::size_t i = 0;
  const auto find = [&](auto&& accept) {
    for (; i < ids.size(); ++i)
      if (accept(points[ids[i]])) return true;
    return false;
  };
  if (ids.empty()) return false;
  t[0] = ids[0];
  const Vec3 &a = points[t[0]];
  if (!find([&](const Vec3& q) { return q != a; })) return false;
  t[1] = ids[i];
  const Vec3& b = points[t[1]];
  if (!find([&](const Vec3& q) { return !collinear(a, b, q); })) return false;
  t[2] = ids[i];
  const detail::OrientPlane plane(a, b, points[t[2]]);
  if (!find([&](const Vec3& q) { return plane.sign(q) != 0; })) return false;
  t[3] = ids[i];
  return true;
}

void build_adjacency(ConvexHull3& out, State& s) {
  const std::size_t n = out.vertices.size();
  s.degree.assign(n, 0);
  for (const HullEdge& e : out.edges) {
    ++s.degree[e.vertex[0]];
    ++s.degree[e.vertex[1]];
  }
  out.neighbor_offsets.assign(n + 1, 0);
  for (std::size_t v = 0; v < n; ++v) out.neighbor_offsets[v + 1] = out.neighbor_offsets[v] + s.degree[v];
  out.neighbors.assign(out.neighbor_offsets[n], 0);
  for (std::size_t v = 0; v < n; ++v) s.degree[v] = out.neighbor_offsets[v];
  for (const HullEdge& e : out.edges) {
    out.neighbors[s.degree[e.vertex[0]]++] = e.vertex[1];
    out.neighbors[s.degree[e.vertex[1]]++] = e.vertex[0];
  }
}

// Planar (or nearly planar) input: the 2D hull in the plane through the set.
void planar_hull(std::span<const Vec3> points, const Vec3& origin, const Vec3& normal, State& s, ConvexHull3& out) {
  const Vec3 u = normal.unitOrthogonal();
  const Vec3 w = normal.cross(u);
  s.plane_points.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - origin;
    s.plane_points[i] = Vec2(u.dot(d), w.dot(d));
  }
  // Monotone chain on the in-plane coordinates, carrying the input ids along.
  s.plane_ids.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) s.plane_ids[i] = static_cast<std::uint32_t>(i);
  const auto& pp = s.plane_points;
  std::sort(s.plane_ids.begin(), s.plane_ids.end(), [&](std::uint32_t a, std::uint32_t b) {
    return pp[a].x() < pp[b].x() || (pp[a].x() == pp[b].x() && pp[a].y() < pp[b].y());
  });
  const auto cross = [&](std::uint32_t o, std::uint32_t a, std::uint32_t b) {
    const Vec2 oa = pp[a] - pp[o], ob = pp[b] - pp[o];
    return oa.x() * ob.y() - oa.y() * ob.x();
  };
  std::vector<std::uint32_t>& h = s.degree;  // reused as the chain buffer
  h.assign(2 * points.size() + 1, 0);
  std::size_t k = 0;
  for (std::uint32_t id : s.plane_ids) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], id) <= 0) --k;
    h[k++] = id;
  }
  const std::size_t lower = k + 1;
  for (std::size_t i = s.plane_ids.size(); i-- > 0;) {
    const std::uint32_t id = s.plane_ids[i];
    while (k >= lower && cross(h[k - 2], h[k - 1], id) <= 0) --k;
    h[k++] = id;
  }
  if (k > 1) --k;
  for (std::size_t i = 0; i < k; ++i) {
    out.vertices.push_back(points[h[i]]);
    out.input_index.push_back(h[i]);
  }
  out.plane_normal = normal;
  out.dimension = out.vertices.size() >= 3 ? 2 : static_cast<int>(out.vertices.size()) - 1;
}

}  // namespace

ConvexHull3 convex_hull(std::span<const Vec3> points) {
  ConvexHull3 out;
  HullWorkspace workspace;
  convex_hull(points, out, workspace);
  return out;
}

void convex_hull(std::span<const Vec3> points, ConvexHull3& out, HullWorkspace& workspace) {
  out.clear();
  if (points.empty()) throw InputError("convex_hull: empty point set");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 4))
    throw InputError("convex_hull: too many points");
  State& s = workspace.state();
  const AffineDimension shape = affine_dimension(points);
  const std::uint32_t ia = shape.simplex[0];
  if (shape.dimension == 0) {
    out.dimension = 0;
    out.vertices.push_back(points[ia]);
    out.input_index.push_back(ia);
    return;
  }
  if (shape.dimension == 1) {
    // The two extreme points along the line.
    const Vec3& dir = shape.direction;
    std::uint32_t lo = ia, hi = ia;
    double t_lo = 0.0, t_hi = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double t = (points[i] - points[ia]).dot(dir);
      if (t < t_lo) t_lo = t, lo = static_cast<std::uint32_t>(i);
      if (t > t_hi) t_hi = t, hi = static_cast<std::uint32_t>(i);
    }
    out.dimension = 1;
    out.vertices = {points[lo], points[hi]};
    out.input_index = {lo, hi};
    return;
  }
  if (shape.dimension == 2) {
    planar_hull(points, shape.bounds.center(), shape.normal, s, out);
    return;
  }

  s.candidates.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) s.candidates[i] = static_cast<std::uint32_t>(i);
  Quickhull hull(points, shape.bounds.extents(), s);
  hull.run(shape.simplex);
  if (!hull.remove_non_extreme_vertices() || !convert(points, s, out)) {
    // Some vertices lie inside a flat facet or an edge of the hull (ties for the farthest point
    // on coplanar sets) and removing them locally failed: rebuild from the strictly extreme
    // vertices only, whose hull is the same polytope and has no other vertices. A failed local
    // removal may have left the faces half edited, so their hull is first built anew.
    hull.run(shape.simplex);
    if (convert(points, s, out)) {
      out.dimension = 3;
      build_adjacency(out, s);
      return;
    }
    keep_extreme_vertices(out, s);
    std::array<std::uint32_t, 4> t{};
    // The strictly extreme points of a solid set span it, so both failures are internal errors.
    if (!exact_simplex(points, s.candidates, t))
      throw std::logic_error("convex_hull: no solid simplex among the strictly extreme points");
    hull.run(t);
    if (!convert(points, s, out)) throw std::logic_error("convex_hull: a vertex is not extreme after the rebuild");
  }
  out.dimension = 3;
  build_adjacency(out, s);
}

AffineDimension affine_dimension(std::span<const Vec3> points) {
  if (points.empty()) throw InputError("affine_dimension: empty point set");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      throw InputError("point " + std::to_string(i) + " has a non-finite coordinate (NaN or Inf)");
  AffineDimension out;
  // Two extreme points a, b along the longest bounding-box axis, the point c farthest from line
  // ab, the point d farthest from plane abc.
  const Aabb& bounds = out.bounds = bounds_of(points);
  int axis = 0;
  bounds.extents().maxCoeff(&axis);
  std::size_t ia = 0, ib = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i][axis] < points[ia][axis]) ia = i;
    if (points[i][axis] > points[ib][axis]) ib = i;
  }
  out.simplex = {static_cast<std::uint32_t>(ia), static_cast<std::uint32_t>(ib), 0, 0};
  const double length = (points[ib] - points[ia]).norm();
  // Differences at the rounding level of the coordinates themselves count as a single point.
  if (!(length > 1e-15 * bounds.center().cwiseAbs().maxCoeff()) || length == 0.0) return out;
  out.direction = (points[ib] - points[ia]) / length;
  const auto [ic, best] = farthest_from_line(points, points[ia], out.direction);
  out.simplex[2] = static_cast<std::uint32_t>(ic);
  out.dimension = 1;
  if (!(std::sqrt(best) > kFlatTolerance * length)) return out;
  out.normal = (points[ib] - points[ia]).cross(points[ic] - points[ia]).normalized();
  double height = 0.0;
  std::size_t id = ia;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double h = std::abs((points[i] - points[ia]).dot(out.normal));
    if (h > height) height = h, id = i;
  }
  out.simplex[3] = static_cast<std::uint32_t>(id);
  out.dimension = 2;
  if (!(height > kFlatTolerance * length) || detail::orient3d(points[ia], points[ib], points[ic], points[id]) == 0)
    return out;
  out.dimension = 3;
  return out;
}

FarthestFromLine farthest_from_line(std::span<const Vec3> points, const Vec3& through, const Vec3& dir) {
  FarthestFromLine out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - through;
    const double dist = (d - d.dot(dir) * dir).squaredNorm();
    if (dist > out.squared_distance) out = {i, dist};
  }
  return out;
}

std::size_t convex_hull_2d(std::span<Vec2> points) {
  std::vector<Vec2> chain;
  return convex_hull_2d(points, chain);
}

std::size_t convex_hull_2d(std::span<Vec2> points, std::vector<Vec2>& chain) {
  const std::size_t n = points.size();
  if (n == 0) return 0;
  std::sort(points.begin(), points.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  chain.resize(2 * n + 1);
  // The exact sign, not the rounded cross product: with rounded signs a nearly collinear point
  // can be kept by both the lower and the upper chain, and the chain outgrows the input.
  const auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return detail::orient2d(o.x(), o.y(), a.x(), a.y(), b.x(), b.y());
  };
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (k >= 2 && cross(chain[k - 2], chain[k - 1], points[i]) <= 0) --k;
    chain[k++] = points[i];
  }
  const std::size_t lower = k + 1;
  for (std::size_t i = n - 1; i-- > 0;) {
    while (k >= lower && cross(chain[k - 2], chain[k - 1], points[i]) <= 0) --k;
    chain[k++] = points[i];
  }
  if (k > 1) --k;  // the last point repeats the first
  // All points equal: the chain is [p, p]; collapse.
  if (k == 2 && chain[0] == chain[1]) k = 1;
  std::copy(chain.begin(), chain.begin() + static_cast<std::ptrdiff_t>(k), points.begin());
  return k;
}

}  // namespace tightbvh
