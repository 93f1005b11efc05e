#pragma once
// Quickhull's internals (internal header): the faces under construction, the hull workspace's
// state (HullWorkspace::State, also used by hull.cpp's conversion and planar code) and the
// Quickhull class itself (quickhull.cpp). The public entry point is convex_hull() (hull.cpp).
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "predicates.hpp"
#include "tightbvh/hull.hpp"

namespace tightbvh {
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

namespace quickhull {

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
  [[nodiscard]] bool remove_non_extreme_vertices();

  // Builds the hull of points[s.candidates] from the exactly non-degenerate tetrahedron
  // `simplex` (candidate ids) into s.faces; starts afresh on every call.
  void run(const std::array<std::uint32_t, 4>& simplex);

 private:
  std::span<const Vec3> p_;
  State& s_;
  Vec3 extent_;
  std::uint32_t next_plane_id_ = 0;
  std::size_t live_ = 0;  // points in outside sets of live faces

  // Documented at their definitions (quickhull.cpp). Declared inline, so that they inline as
  // member functions defined in the class would (only quickhull.cpp calls them).
  inline std::uint32_t new_face(std::uint32_t a, std::uint32_t b, std::uint32_t c);
  inline bool coplanar(std::uint32_t f, std::uint32_t g) const;

  inline bool remove_vertex(std::uint32_t v);
  inline bool attach(std::uint32_t a, std::uint32_t b, std::uint32_t outer);
  inline bool triangulate(std::uint32_t plane_face);
  inline void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t plane_id);

  // Ranks outside points: by distance, and among (nearly) equally far ones the lexicographically
  // largest, which is a vertex of their hull: ties along a line or plane parallel to the face
  // (ruled and flat CAD surfaces) then pick an end point, not one that later lies on an edge.
  static constexpr double kTie = 1e-12;
  static inline bool farther(const Vec3& a, double a_value, const Vec3& b, double b_value);
  inline void claim(std::uint32_t f);
  inline void compact_pool();
  static inline std::uint32_t slot_of_edge(const Face& face, std::uint32_t from, std::uint32_t to);
  inline void start(std::array<std::uint32_t, 4> t);
  inline void find_visible(std::uint32_t seed, std::uint32_t apex, std::uint32_t stamp);
  inline void order_horizon();
  inline void add_point(std::uint32_t seed, std::uint32_t apex, std::uint32_t stamp);
};

}  // namespace quickhull
}  // namespace tightbvh
