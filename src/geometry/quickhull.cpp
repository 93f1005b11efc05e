// Quickhull (Barber, Dobkin & Huhdanpaa 1996, "The Quickhull algorithm for convex hulls", ACM
// TOMS 22(4)) with exact orientation predicates; see hull.cpp for the robustness argument and
// quickhull.hpp for the class.
#include "quickhull.hpp"

#include <algorithm>
#include <cmath>

#include "tightbvh/mesh.hpp"

namespace tightbvh::quickhull {

// The farthest-point picks can leave a vertex inside a flat facet or inside an edge of the
// hull (ties on coplanar and collinear sets). Removes those vertices by triangulating the
// planar polygon(s) around each (their links); false when that fails (never expected).
bool Quickhull::remove_non_extreme_vertices() {
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

void Quickhull::run(const std::array<std::uint32_t, 4>& simplex) {
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

std::uint32_t Quickhull::new_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
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
bool Quickhull::coplanar(std::uint32_t f, std::uint32_t g) const {
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
bool Quickhull::remove_vertex(std::uint32_t v) {
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
bool Quickhull::attach(std::uint32_t a, std::uint32_t b, std::uint32_t outer) {
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
bool Quickhull::triangulate(std::uint32_t plane_face) {
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

void Quickhull::add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t plane_id) {
  const std::uint32_t f = new_face(a, b, c);
  s_.faces[f].plane_id = plane_id;
  s_.open_faces.push_back(f);
  for (std::uint32_t k = 0; k < 3; ++k) s_.open_edges.push_back({f, k});
  for (std::uint32_t v : {a, b, c}) s_.corner_face[v] = f;
}

// See kTie (quickhull.hpp).
bool Quickhull::farther(const Vec3& a, double a_value, const Vec3& b, double b_value) {
  if (a_value > b_value * (1 + kTie)) return true;
  if (a_value < b_value * (1 - kTie)) return false;
  return a.x() > b.x() || (a.x() == b.x() && (a.y() > b.y() || (a.y() == b.y() && a.z() > b.z())));
}

// Moves the points of s.unassigned that are strictly above face f into f's outside set (at
// the end of the pool) and keeps the others in s.unassigned, in order.
void Quickhull::claim(std::uint32_t f) {
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
void Quickhull::compact_pool() {
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
std::uint32_t Quickhull::slot_of_edge(const Face& face, std::uint32_t from, std::uint32_t to) {
  for (std::uint32_t k = 0; k < 3; ++k)
    if (face.vertex[(k + 1) % 3] == from && face.vertex[(k + 2) % 3] == to) return k;
  return kNone;
}

void Quickhull::start(std::array<std::uint32_t, 4> t) {
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
void Quickhull::find_visible(std::uint32_t seed, std::uint32_t apex, std::uint32_t stamp) {
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
void Quickhull::order_horizon() {
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

void Quickhull::add_point(std::uint32_t seed, std::uint32_t apex, std::uint32_t stamp) {
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

}  // namespace tightbvh::quickhull
