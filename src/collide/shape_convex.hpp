// The cylinder and the convex hull against a triangle, in the mesh frame: the Placed types of
// shape_query.cpp. Included by shape_query.cpp inside its anonymous namespace, after Measure,
// frame_of(), box_bound(), interval_gap() and needed_gap(), which these use. See include/tightbvh/shape.hpp.

// The gap between the triangle's bounding box and the box [lo, hi] (squared), and the scale of
// their coordinates.
[[nodiscard]] inline double boxes_gap2(const std::array<Vec3, 3>& v, const Vec3& lo_s, const Vec3& hi_s,
                                       double& scale) {
  const Vec3 lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = interval_gap(lo[k], hi[k], lo_s[k], hi_s[k]);
    sum += g * g;
  }
  scale = std::max({hi.cwiseAbs().maxCoeff(), lo.cwiseAbs().maxCoeff(), hi_s.cwiseAbs().maxCoeff(),
                    lo_s.cwiseAbs().maxCoeff()});
  return sum;
}

// The gap along w, from the shape's center to the node's (mesh frame), given the shape's reach
// along it scaled by |w| (its greatest w . (x - center)): |w| less both reaches (the node's
// sum_i e_i |a_i . w| / |w|), shrunk for the float axes and less the allowance as box_bound();
// 0 where it does not separate.
[[nodiscard]] inline double centers_gap(const CompactBox& node, const Vec3& w, double shape_reach, double allowance) {
  const double w2 = w.squaredNorm();
  if (!(w2 > 0.0)) return 0.0;
  double reach = shape_reach;
  for (int i = 0; i < 3; ++i)
    reach += static_cast<double>(node.half_extents[i]) * std::abs(node.axes.col(i).cast<double>().dot(w));
  const double along = w2 - reach;
  if (!(along > 0.0)) return 0.0;
  return std::max(0.0, along / std::sqrt(w2) * (1.0 - kCompactBoxSlack) - allowance);
}

// The triangle's corner of greatest d . x.
[[nodiscard]] inline Vec3 triangle_support(const std::array<Vec3, 3>& v, const Vec3& d) {
  const double p0 = d.dot(v[0]), p1 = d.dot(v[1]), p2 = d.dot(v[2]);
  if (p0 >= p1 && p0 >= p2) return v[0];
  return p1 >= p2 ? v[1] : v[2];
}

// A cylinder in the mesh frame; triangles are mapped into its own frame, where its axis is z.
struct PlacedCylinder {
  Pose to_local;
  Pose to_mesh;
  double r, hz;
  Obb box;

  PlacedCapsule hull;  // the capsule of the same radius and axis, which holds the cylinder

  PlacedCylinder(const Cylinder& s, const Pose& rel)
      : to_local(rel.inverse()),
        to_mesh(rel),
        r(s.radius),
        hz(0.5 * s.length),
        box{rel.translation, rel.rotation, Vec3(s.radius, s.radius, 0.5 * s.length)},
        hull(Capsule(s.radius, s.length), rel) {}

  [[nodiscard]] std::array<Vec3, 3> mapped(const Vec3& a, const Vec3& b, const Vec3& c) const {
    return {map_point(to_local, a), map_point(to_local, b), map_point(to_local, c)};
  }
  // The cylinder's point of greatest d . x: on the rim of the cap d_z points to.
  [[nodiscard]] Vec3 support(const Vec3& d) const {
    const double n = std::hypot(d.x(), d.y());
    const double z = d.z() >= 0.0 ? hz : -hz;
    if (!(n > 0.0)) return Vec3(0.0, 0.0, z);
    return Vec3(r * d.x() / n, r * d.y() / n, z);
  }
  [[nodiscard]] double scale_of(const std::array<Vec3, 3>& v) const {
    return std::max({r, hz, v[0].cwiseAbs().maxCoeff(), v[1].cwiseAbs().maxCoeff(), v[2].cwiseAbs().maxCoeff()});
  }
  // GJK between the cylinder (A) and the triangle (B), cylinder frame; stops within 1e-12 of the
  // distance or 1e-12 of the scale.
  // With decide >= 0, only until "distance <= decide?" is settled (gjk::distance).
  [[nodiscard]] gjk::Result run(const std::array<Vec3, 3>& v, double scale, double decide = -1.0) const {
    const Vec3 start = (v[0] + v[1] + v[2]) / 3.0;
    return gjk::distance([&](const Vec3& d) { return support(d); },
                         [&](const Vec3& d) { return triangle_support(v, d); }, Vec3(0.0, 0.0, 0.0), start,
                         1e-12 * scale, 1e-12, 128, decide);
  }
  [[nodiscard]] Measure measure(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const std::array<Vec3, 3> v = mapped(a, b, c);
    const double scale = scale_of(v);
    const gjk::Result g = run(v, scale);
    if (g.distance <= kCylinderTolerance * scale) {
      const Vec3 p = to_mesh.apply(g.point_b);
      return {0.0, p, p};
    }
    // GJK's point of the cylinder is a combination of rim points, so it may lie a little inside a
    // curved side; the cylinder's exact closest point to GJK's point of the triangle is on the
    // surface and no farther (the distance stays an upper bound, within GJK's accuracy).
    const Vec3 on = closest_point(g.point_b);
    const double d = std::max((on - g.point_b).norm(), std::numeric_limits<double>::min());  // disjoint: never 0
    return {d, to_mesh.apply(on), to_mesh.apply(g.point_b)};
  }
  // The solid cylinder's closest point to x (the disc and the interval apart: clamp each).
  [[nodiscard]] Vec3 closest_point(const Vec3& x) const {
    const double rho = std::hypot(x.x(), x.y());
    const double s = rho > r ? r / rho : 1.0;
    return Vec3(x.x() * s, x.y() * s, std::clamp(x.z(), -hz, hz));
  }
  // The larger of the bound of the capsule that holds the cylinder (its segment bound less the
  // radius: about as tight as the cylinder's box against the node's, for a third of its cost) and
  // the gap along the line of the centers, w: |w| less the cylinder's reach along it (|w_z| hz +
  // r |w_xy| in its frame) and the node's (sum_i e_i |a_i . w| / |w|), scaled by |w|, which is
  // the tighter one for a squat cylinder seen across its caps' edges.
  [[nodiscard]] double lower_bound(const CompactBox& node, double allowance) const {
    return std::max(hull.lower_bound(node, allowance), along_bound(node, allowance));
  }
  // The gap along the line of the centers alone (0 where it does not separate).
  [[nodiscard]] double along_bound(const CompactBox& node, double allowance) const {
    const Vec3 w = node.center_d() - box.center;
    const Vec3 local = to_local.rotation * w;
    return centers_gap(node, w, std::abs(local.z()) * hz + r * std::hypot(local.x(), local.y()), allowance);
  }
  // Nothing in the node is within `margin`: its lower bound says so, as the sphere's and the
  // capsule's (both of its parts are cheap; tighter than the cylinder's box against the node's).
  [[nodiscard]] bool apart(const CompactBox& node, double allowance, double margin) const {
    return lower_bound(node, allowance) > margin;
  }
  // The gap between the triangle's bounding box and the cylinder's (cylinder frame) against the
  // limit, as the box's ruled_out(); then the cylinder's gap to the triangle's plane (its extent
  // along the normal n is n . 0 -+ (|n_z| hz + r |n_xy|)).
  [[nodiscard]] bool ruled_out(const Vec3& a, const Vec3& b, const Vec3& c, double limit) const {
    if (!(limit < std::numeric_limits<double>::infinity())) return false;
    const std::array<Vec3, 3> v = mapped(a, b, c);
    double scale = 0.0;
    const double gap2 = boxes_gap2(v, Vec3(-r, -r, -hz), Vec3(r, r, hz), scale);
    const double need = needed_gap(limit, 0.0, scale);
    return gap2 >= need * need || plane_apart(v, need);
  }
  // The cylinder's gap to the triangle's plane is at least `need` (its extent along the normal n
  // is n . 0 -+ (|n_z| hz + r |n_xy|)).
  [[nodiscard]] bool plane_apart(const std::array<Vec3, 3>& v, double need) const {
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    const double reach = std::abs(n.z()) * hz + r * std::hypot(n.x(), n.y()), at = -n.dot(v[0]);
    return plane_rules_out(n, at - reach, at + reach, need);
  }
  [[nodiscard]] bool within(const Vec3& a, const Vec3& b, const Vec3& c, double margin) const {
    const std::array<Vec3, 3> v = mapped(a, b, c);
    double scale = 0.0;
    const double gap2 = boxes_gap2(v, Vec3(-r, -r, -hz), Vec3(r, r, hz), scale);
    const double need = needed_gap(margin, 0.0, scale) + kCylinderTolerance * scale;
    // The boxes' gap, then the plane's, bound the distance from below.
    if (gap2 > need * need || plane_apart(v, need)) return false;
    // measure(a, b, c).distance <= margin, settled early where GJK's bounds decide it with room to
    // spare (relative 1e-9, far above rounding): measure()'s distance, or its touching test, is
    // at least GJK's lower bound and at most its current |v| (which only decreases). Between
    // them, measure() itself decides, so the two never disagree.
    const double tolerance = kCylinderTolerance * scale_of(v), threshold = std::max(tolerance, margin);
    const gjk::Result g = run(v, scale_of(v), threshold);
    if (g.lower > threshold * (1.0 + 1e-9)) return false;
    if (g.distance < threshold * (1.0 - 1e-9)) return true;
    return measure(a, b, c).distance <= margin;
  }
};

// The relative accuracy GJK must prove (its upper bound within this of its lower bound) for a
// hull's distance to a triangle; else the exact minimum over the faces is measured. Tenfold below
// the 1e-12 the distance queries promise.
constexpr double kConvexGjkRelative = 1e-13;

// A convex hull in the mesh frame; triangles are mapped into its own frame, where its faces'
// planes are prepared for exact orientation tests (Shewchuk's orient3d, predicates.hpp).
struct PlacedConvex {
  const Convex* hull;
  Pose to_local;
  Pose to_mesh;
  Vec3 lo, hi;  // the vertices' box, hull frame
  Obb box;
  // The faces' planes and boxes, made at the first triangle test (a query that culls every node,
  // the common case, never needs them).
  mutable std::vector<tightbvh::detail::OrientPlane> planes;
  mutable std::vector<Vec3> face_lo, face_hi;
  mutable std::vector<signed char> sides;  // scratch: per face, the corners' orientation signs

  PlacedConvex(const Convex& s, const Pose& rel) : hull(&s), to_local(rel.inverse()), to_mesh(rel) {
    lo = hi = s.vertices.front();
    for (const Vec3& p : s.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    box = Obb{rel.apply(0.5 * (lo + hi)), rel.rotation, 0.5 * (hi - lo)};
  }

  void prepare_faces() const {
    if (!planes.empty()) return;
    const Convex& s = *hull;
    planes.reserve(s.faces.size());
    face_lo.reserve(s.faces.size());
    face_hi.reserve(s.faces.size());
    for (const auto& f : s.faces) {
      const Vec3 &p = s.vertices[f[0]], &q = s.vertices[f[1]], &t = s.vertices[f[2]];
      planes.emplace_back(p, q, t);
      face_lo.push_back(p.cwiseMin(q).cwiseMin(t));
      face_hi.push_back(p.cwiseMax(q).cwiseMax(t));
    }
    sides.resize(3 * s.faces.size());
  }

  [[nodiscard]] std::array<Vec3, 3> mapped(const Vec3& a, const Vec3& b, const Vec3& c) const {
    return {map_point(to_local, a), map_point(to_local, b), map_point(to_local, c)};
  }
  // The hull's vertex of greatest d . x (a scan: on ~30 vertices cheaper than hill climbing).
  [[nodiscard]] Vec3 support(const Vec3& d) const {
    std::size_t best = 0;
    double top = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hull->vertices.size(); ++i) {
      const double p = d.dot(hull->vertices[i]);
      if (p > top) top = p, best = i;
    }
    return hull->vertices[best];
  }
  [[nodiscard]] std::array<Vec3, 3> face(std::size_t f) const {
    const auto& i = hull->faces[f];
    return {hull->vertices[i[0]], hull->vertices[i[1]], hull->vertices[i[2]]};
  }

  // Exact on the hull-frame coordinates: -1 when a face plane has every corner strictly outside
  // (it separates) or when no corner is in the closed hull and no face touches the triangle (a
  // triangle that touches the solid without a corner in it crosses its surface); else the index
  // of a corner in the hull (0..2) or 3 + a touched face. A face whose plane has every corner
  // strictly inside cannot be touched, so only the others go to tri_tri_overlap. Fills `sides`.
  [[nodiscard]] int touching(const std::array<Vec3, 3>& v) const {
    prepare_faces();
    const std::size_t nf = planes.size();
    bool inside[3] = {true, true, true};
    for (std::size_t f = 0; f < nf; ++f) {
      int outside = 0;
      for (int i = 0; i < 3; ++i) {
        const int s = planes[f].sign(v[i]);
        sides[3 * f + i] = static_cast<signed char>(s);
        if (s > 0) ++outside, inside[i] = false;
      }
      if (outside == 3) return -1;
    }
    for (int i = 0; i < 3; ++i)
      if (inside[i]) return i;
    for (std::size_t f = 0; f < nf; ++f) {
      if (sides[3 * f] < 0 && sides[3 * f + 1] < 0 && sides[3 * f + 2] < 0) continue;
      const std::array<Vec3, 3> t = face(f);
      if (tri_tri_overlap(t[0], t[1], t[2], v[0], v[1], v[2])) return 3 + static_cast<int>(f);
    }
    return -1;
  }

  // A disjoint triangle's closest point y and the hull's x have y - x in the hull's normal cone
  // at x, so x lies on a face whose plane y, hence a corner, is strictly outside of (`sides` from
  // touching()): the least tri_tri_distance over those faces is the distance. Faces whose box is
  // already as far as the best so far are skipped.
  [[nodiscard]] TriangleDistance disjoint_distance(const std::array<Vec3, 3>& v) const {
    TriangleDistance best;
    best.distance = std::numeric_limits<double>::infinity();
    const Vec3 tlo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), thi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
    for (std::size_t f = 0; f < planes.size(); ++f) {
      if (sides[3 * f] <= 0 && sides[3 * f + 1] <= 0 && sides[3 * f + 2] <= 0) continue;
      double gap2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double g = interval_gap(tlo[k], thi[k], face_lo[f][k], face_hi[f][k]);
        gap2 += g * g;
      }
      if (gap2 >= best.distance * best.distance) continue;
      const std::array<Vec3, 3> t = face(f);
      const TriangleDistance d = tri_tri_distance(t[0], t[1], t[2], v[0], v[1], v[2]);
      if (d.distance < best.distance) best = d;
    }
    best.distance = std::max(best.distance, std::numeric_limits<double>::min());  // disjoint: never 0
    return best;
  }

  [[nodiscard]] Measure measure(const Vec3& a, const Vec3& b, const Vec3& c) const {
    const std::array<Vec3, 3> v = mapped(a, b, c);
    const int touch = touching(v);
    if (touch >= 0) {
      Vec3 point = touch < 3 ? v[touch] : tri_tri_distance(face(touch - 3), v).point_q;
      point = to_mesh.apply(point);
      return {0.0, point, point};
    }
    // Disjoint: GJK first (the hull's support a scan of its vertices), kept when its lower bound
    // certifies it within kConvexGjkRelative of the true distance (lower <= true <= upper);
    // otherwise (not converged, or overlapping in rounding) the faces' exact minimum.
    const double scale = std::max({hi.cwiseAbs().maxCoeff(), lo.cwiseAbs().maxCoeff(), v[0].cwiseAbs().maxCoeff(),
                                   v[1].cwiseAbs().maxCoeff(), v[2].cwiseAbs().maxCoeff()});
    const gjk::Result g = gjk::distance([&](const Vec3& d) { return support(d); },
                                        [&](const Vec3& d) { return triangle_support(v, d); },
                                        hull->vertices.front(), v[0], 1e-15 * scale, 1e-15);
    if (!g.overlapping && g.distance > 0.0 && g.distance - g.lower <= kConvexGjkRelative * g.lower)
      return {g.distance, to_mesh.apply(g.point_a), to_mesh.apply(g.point_b)};
    // A separating face plane ended touching() early: classify every face for the distance.
    for (std::size_t f = 0; f < planes.size(); ++f)
      for (int i = 0; i < 3; ++i) sides[3 * f + i] = static_cast<signed char>(planes[f].sign(v[i]));
    const TriangleDistance best = disjoint_distance(v);
    return {best.distance, to_mesh.apply(best.point_p), to_mesh.apply(best.point_q)};
  }
  // The larger of the hull's box against the node's (box_bound) and the gap along the line from
  // the box's center to the node's, w: |w| less the hull's own reach along it (its vertices'
  // greatest w . (p - center), a scan) and the node's (sum_i e_i |a_i . w| / |w|), scaled by |w|.
  // A hull is smaller than its box (round hulls lose their corners), so the second is the tighter
  // one where the two are far apart for their sizes; shrunk and less the allowance as box_bound.
  [[nodiscard]] double lower_bound(const CompactBox& node, double allowance) const {
    return std::max(box_bound(node, box, allowance), along_bound(node, allowance));
  }
  // The gap along the line of the centers alone (0 where it does not separate).
  [[nodiscard]] double along_bound(const CompactBox& node, double allowance) const {
    const Vec3 w = node.center_d() - box.center;
    const Vec3 local = to_local.rotation * w, center = 0.5 * (lo + hi);
    double reach = -std::numeric_limits<double>::infinity();
    for (const Vec3& p : hull->vertices) reach = std::max(reach, local.dot(p - center));
    return centers_gap(node, w, reach, allowance);
  }
  // Nothing in the node is within `margin`: the shape's box against the node's (obb_overlap, as
  // the box's), then, for a node it lets through, the gap along the line of the centers.
  [[nodiscard]] bool apart(const CompactBox& node, double allowance, double margin) const {
    const query_detail::BoxFrame f = frame_of(node, box);
    return !obb_overlap(f.c, f.d, node.half_extents_d(), box.half_extents, allowance + margin) ||
           along_bound(node, allowance) > margin;
  }
  // The gap between the triangle's bounding box and the hull's, then the hull's gap to the
  // triangle's plane (its extent along the normal: a scan of the vertices, far cheaper than GJK).
  [[nodiscard]] bool ruled_out(const Vec3& a, const Vec3& b, const Vec3& c, double limit) const {
    if (!(limit < std::numeric_limits<double>::infinity())) return false;
    const std::array<Vec3, 3> v = mapped(a, b, c);
    double scale = 0.0;
    const double gap2 = boxes_gap2(v, lo, hi, scale);
    const double need = needed_gap(limit, 0.0, scale);
    return gap2 >= need * need || plane_apart(v, need);
  }
  // The hull's gap to the triangle's plane is at least `need` (its extent along the normal: a scan
  // of the vertices).
  [[nodiscard]] bool plane_apart(const std::array<Vec3, 3>& v, double need) const {
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (const Vec3& p : hull->vertices) {
      const double at = n.dot(p - v[0]);
      low = std::min(low, at), high = std::max(high, at);
    }
    return plane_rules_out(n, low, high, need);
  }
  [[nodiscard]] bool within(const Vec3& a, const Vec3& b, const Vec3& c, double margin) const {
    const std::array<Vec3, 3> v = mapped(a, b, c);
    double scale = 0.0;
    const double gap2 = boxes_gap2(v, lo, hi, scale);
    const double need = needed_gap(margin, 0.0, scale);
    // The boxes' gap, then the plane's, bound the distance from below.
    if (gap2 > need * need || plane_apart(v, need)) return false;
    if (touching(v) >= 0) return true;
    if (margin == 0.0) return false;
    return measure(a, b, c).distance <= margin;  // measure()'s arithmetic
  }
};
