// Exact minimum-volume box (O'Rourke 1985; the edge-pair families of Eberly 2024, Section 3).
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "fitters.hpp"
#include "frame.hpp"

namespace tightbvh::fit_detail {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Evaluator {
  const HullGeometry& g;
  ExactScratch& s;

  // Volume of the tightest hull box with axes n1, n2, n1 x n2 (n1, n2 unit, orthogonal);
  // the three widths go to `widths`.
  double volume(const Vec3& n1, const Vec3& n2, double* widths) {
    ++s.stats.evaluations;
    const Vec3 n3 = n1.cross(n2);
    const Vec3 axis[3] = {n1, n2, n3};
    double v = 1.0;
    for (int k = 0; k < 3; ++k) {
      s.hints[2 * k] = extreme_vertex(g, axis[k], s.hints[2 * k]);
      s.hints[2 * k + 1] = extreme_vertex(g, -axis[k], s.hints[2 * k + 1]);
      const double w = axis[k].dot(g.local[s.hints[2 * k]] - g.local[s.hints[2 * k + 1]]);
      if (widths) widths[k] = w;
      v *= w;
    }
    return v;
  }

  // The family of edge pair (i, j): n1(t) on arc i, n2 = n1 x d_j normalised.
  bool frame(std::size_t i, std::size_t j, double t, Vec3& n1, Vec3& n2, double* m_len = nullptr) const {
    const auto& ai = s.arcs[i];
    n1 = std::cos(t) * ai.a + std::sin(t) * ai.b;
    const Vec3 m = n1.cross(s.arcs[j].d);
    const double len = m.norm();
    if (m_len) *m_len = len;
    // Near n1 = +-d_j the family degenerates (n2 turns freely); the ordered pair (j, i)
    // parameterises that part.
    if (!(len > 1e-9)) return false;
    n2 = m / len;
    return true;
  }

  double at(std::size_t i, std::size_t j, double t, double* widths = nullptr, double* m_len = nullptr) {
    Vec3 n1, n2;
    if (!frame(i, j, t, n1, n2, m_len)) return kInf;
    // The box face with normal n1 touches edge i; the one with normal +-n2 touches edge j.
    s.hints[0] = s.arcs[i].v0;
    if (n2.dot(s.arcs[j].a) + n2.dot(s.arcs[j].b) < 0.0) n2 = -n2;
    s.hints[2] = s.arcs[j].v0;
    return volume(n1, n2, widths);
  }
};

// The best box so far. Hill climbing (extreme_vertex) can stop short of the maximum where a
// vertex's better neighbours tie with it in floating point: a vertex of the exact hull that
// bulges out of a flat facet by less than the rounding, climbed along that facet's normal. Such
// a width is too small, so a volume is only taken as the best so far after box_of_hull (a scan
// of every vertex) confirms it; the lower bounds of phase 3 stay valid with too small widths.
struct Incumbent {
  const HullGeometry& g;
  AxisBox box;
  double volume;

  // Takes `candidate`'s axes if their confirmed box beats the best so far.
  void offer(const AxisBox& candidate) {
    if (!(candidate.volume() < volume)) return;
    const AxisBox checked = box_of_hull(g, candidate.axes);
    if (checked.volume() < volume) volume = checked.volume(), box = checked;
  }
};

// Phase 1: boxes with a face flush with a hull face, by Bopt along each distinct face normal;
// then a good first upper bound, which lets phase 3's bounds skip most families: the grid
// search of Section 6.4 with k = 2 and the local improvement (any valid box is a valid bound).
void face_boxes(const HullGeometry& g, ExactScratch& s, BoptScratch& bs, Incumbent& best) {
  const ConvexHull3& hull = *g.hull;
  const std::size_t nf = hull.faces.size();
  s.face_order.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) s.face_order[f] = static_cast<std::uint32_t>(f);
  const auto& normals = hull.face_normals;
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    const Vec3 &x = normals[a], &y = normals[b];
    return x.x() < y.x() || (x.x() == y.x() && (x.y() < y.y() || (x.y() == y.y() && x.z() < y.z())));
  };
  std::sort(s.face_order.begin(), s.face_order.end(), less);
  for (std::size_t k = 0; k < nf; ++k) {
    const std::uint32_t f = s.face_order[k];
    if (k > 0 && normals[f] == normals[s.face_order[k - 1]]) continue;
    ++s.stats.face_directions;
    best.offer(bopt(g, normals[f], bs));
  }
  best.offer(grid_search(g, lemma_box(g, bs), 2, true, bs));
}

// Phase 2: the normal arcs of the hull's edges (outward normals, rotating from face[0]'s to
// face[1]'s); flat edges (inside a planar face) have none and are covered by phase 1.
void normal_arcs(const HullGeometry& g, ExactScratch& s) {
  const ConvexHull3& hull = *g.hull;
  const auto& normals = hull.face_normals;
  s.arcs.clear();
  for (const HullEdge& e : hull.edges) {
    const Vec3 d = (g.local[e.vertex[1]] - g.local[e.vertex[0]]).normalized();
    Vec3 na = normals[e.face[0]] - normals[e.face[0]].dot(d) * d;
    Vec3 nb = normals[e.face[1]] - normals[e.face[1]].dot(d) * d;
    if (!(na.norm() > 0.0) || !(nb.norm() > 0.0) || !d.allFinite()) continue;
    na.normalize();
    nb.normalize();
    Vec3 b = nb - nb.dot(na) * na;
    const double bl = b.norm();
    if (!(bl > 1e-12)) continue;  // flat edge (inside a planar face): covered by step 1
    b /= bl;
    ExactScratch::Arc arc;
    arc.d = d;
    arc.a = na;
    arc.b = b;
    arc.alpha = std::atan2(nb.dot(b), nb.dot(na));
    arc.v0 = e.vertex[0];
    if (!(arc.alpha > 1e-12)) continue;
    s.arcs.push_back(arc);
  }
}

// Phase 3: families of ordered edge pairs (e1, e2): n1 on arc 1 and n2 = n1 x d2 on arc 2.
// n2 can lie on arc 2 (up to sign) iff n1 separates arc 2's end normals P, Q:
// (P . n1)(Q . n1) <= 0. Each of P . n1(t), Q . n1(t) is a sinusoid with at most one zero
// on [0, alpha1] (alpha1 < pi), so the valid set is at most three intervals cut at those zeros.
//
// Branch and bound over one family t in [t0, t1]: evaluate the middle of an interval,
// bound the volume on the whole interval from below, drop it when the bound reaches the
// best volume so far, else split; intervals shorter than kStep are refined by golden-section
// search. The bound: a support function is R-Lipschitz in the direction (R = max |p|),
// n1 moves at unit speed, n2 = m/|m| with m = n1 x d2 at speed <= 1/|m| (|m| itself moves at
// speed <= 1), n3 = n1 x n2 at <= 1 + 1/|m|; so each width changes by at most 2 R speed |dt|.
class FamilySearch {
 public:
  static constexpr double kStep = 0.01;  // sampling step along a family (radians, ~0.6 degrees)
  static constexpr int kGolden = 60;

  FamilySearch(const HullGeometry& g, ExactScratch& s, Incumbent& best)
      : ev_(Evaluator{g, s}), s_(s), best_(best), best_n1_(best.box.axes.col(0)), best_n2_(best.box.axes.col(1)) {
    for (const Vec3& p : g.local) radius_ = std::max(radius_, p.norm());
  }

  // Every ordered pair of arcs, cut into the intervals where its family exists.
  void run() {
    const std::size_t na = s_.arcs.size();
    for (std::size_t i = 0; i < na; ++i) {
      const auto& a1 = s_.arcs[i];
      const Vec3 end1 = std::cos(a1.alpha) * a1.a + std::sin(a1.alpha) * a1.b;  // arc i's last normal
      for (std::size_t j = 0; j < na; ++j)
        if (j != i) search_pair(i, j, end1);
    }
  }

  // The best family box found, if one beat the incumbent at the time (its confirmed volume is
  // then best.volume); its axes as found, not yet re-orthonormalised.
  [[nodiscard]] bool found() const { return have_family_best_; }
  [[nodiscard]] Mat3 axes() const {
    Mat3 axes;
    axes.col(0) = best_n1_;
    axes.col(1) = best_n2_;
    axes.col(2) = best_n1_.cross(best_n2_);
    return axes;
  }

 private:
  void search_pair(std::size_t i, std::size_t j, const Vec3& end1) {
    const auto& a1 = s_.arcs[i];
    const auto& a2 = s_.arcs[j];
    const Vec3 P = a2.a;
    const Vec3 Q = std::cos(a2.alpha) * a2.a + std::sin(a2.alpha) * a2.b;
    const double p0 = P.dot(a1.a), p1 = P.dot(end1), q0 = Q.dot(a1.a), q1 = Q.dot(end1);
    if (p0 * q0 > 0.0 && p1 * q1 > 0.0 && p0 * p1 > 0.0 && q0 * q1 > 0.0) return;
    // Cut points: zeros of P . n1(t) and Q . n1(t) inside (0, alpha1).
    double cuts[4] = {0.0, 0.0, 0.0, 0.0};
    int nc = 0;
    cuts[nc++] = 0.0;
    for (const Vec3* f : {&P, &Q}) {
      const double A = f->dot(a1.a), B = f->dot(a1.b);
      double z = std::atan2(-A, B);
      if (z < 0.0) z += kPi;
      if (z > 0.0 && z < a1.alpha) cuts[nc++] = z;
    }
    cuts[nc++] = a1.alpha;
    for (int x = 1; x < nc; ++x)  // insertion sort of at most four values
      for (int y = x; y > 0 && cuts[y] < cuts[y - 1]; --y) std::swap(cuts[y], cuts[y - 1]);
    for (int c = 0; c + 1 < nc; ++c) {
      const double t0 = cuts[c], t1 = cuts[c + 1];
      if (!(t1 > t0)) continue;
      const double tm = 0.5 * (t0 + t1);
      const Vec3 nm = std::cos(tm) * a1.a + std::sin(tm) * a1.b;
      if (P.dot(nm) * Q.dot(nm) > 0.0) continue;
      search_family(i, j, t0, t1);
    }
  }

  void record(std::size_t i, std::size_t j, double t, double v) {
    if (!(v < best_.volume)) return;
    Vec3 n1, n2;
    if (!ev_.frame(i, j, t, n1, n2)) return;
    Mat3 axes;
    axes << n1, n2, n1.cross(n2);
    v = box_of_hull(ev_.g, axes).volume();
    if (!(v < best_.volume)) return;
    best_.volume = v;
    best_n1_ = n1;
    best_n2_ = n2;
    have_family_best_ = true;
  }

  // Lower bound of the volume on [t - half, t + half] from the widths w at t (see above).
  [[nodiscard]] double lower_bound(const double* w, double m_len, double half) const {
    const double m_min = m_len - half;
    if (!(m_min > 0.0)) return 0.0;
    const double speed[3] = {1.0, 1.0 / m_min, 1.0 + 1.0 / m_min};
    double bound = 1.0;
    for (int a = 0; a < 3; ++a) bound *= std::max(0.0, w[a] - 2.0 * radius_ * speed[a] * half);
    return bound;
  }

  // Golden-section search on [lo, hi], stopped early as soon as the bound over the remaining
  // bracket (from its best interior point) reaches the best volume so far.
  void golden(std::size_t i, std::size_t j, double lo, double hi) {
    ++s_.stats.refined;
    constexpr double r = 0.6180339887498949;
    double w1[3], w2[3], m1 = 0.0, m2 = 0.0;
    double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
    double f1 = ev_.at(i, j, x1, w1, &m1), f2 = ev_.at(i, j, x2, w2, &m2);
    for (int it = 0; it < kGolden && hi - lo > 1e-13; ++it) {
      if (f1 <= f2) {
        hi = x2, x2 = x1, f2 = f1, m2 = m1;
        std::copy(w1, w1 + 3, w2);
        x1 = hi - r * (hi - lo);
        f1 = ev_.at(i, j, x1, w1, &m1);
      } else {
        lo = x1, x1 = x2, f1 = f2, m1 = m2;
        std::copy(w2, w2 + 3, w1);
        x2 = lo + r * (hi - lo);
        f2 = ev_.at(i, j, x2, w2, &m2);
      }
      record(i, j, x1, f1);
      record(i, j, x2, f2);
      const bool first = f1 <= f2;
      const double x = first ? x1 : x2;
      const double reach = std::max(x - lo, hi - x);
      if (lower_bound(first ? w1 : w2, first ? m1 : m2, reach) >= best_.volume) break;
    }
    record(i, j, x1, f1);
    record(i, j, x2, f2);
  }

  void search_family(std::size_t i, std::size_t j, double t0, double t1) {
    ++s_.stats.edge_pairs;
    std::vector<std::pair<double, double>>& stack = s_.intervals;
    stack.clear();
    record(i, j, t0, ev_.at(i, j, t0));
    record(i, j, t1, ev_.at(i, j, t1));
    stack.emplace_back(t0, t1);
    while (!stack.empty()) {
      const auto [lo, hi] = stack.back();
      stack.pop_back();
      const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
      double w[3], m_len = 0.0;
      const double v = ev_.at(i, j, mid, w, &m_len);
      record(i, j, mid, v);
      if (!(v < kInf) || !(m_len - half > 0.0)) {
        // Close to the singular direction n1 = +-d2 nothing can be bounded; split down to
        // 1e-4 rad, the rest is parameterised well by the ordered pair (j, i).
        if (half > 1e-4) stack.emplace_back(lo, mid), stack.emplace_back(mid, hi);
        continue;
      }
      if (lower_bound(w, m_len, half) >= best_.volume) continue;
      if (2.0 * half <= kStep) {
        golden(i, j, lo, hi);
        continue;
      }
      stack.emplace_back(lo, mid);
      stack.emplace_back(mid, hi);
    }
  }

  Evaluator ev_;
  ExactScratch& s_;
  Incumbent& best_;
  Vec3 best_n1_, best_n2_;
  bool have_family_best_ = false;
  double radius_ = 0.0;
};

}  // namespace

AxisBox exact_box(const HullGeometry& g, ExactScratch& s, BoptScratch& bs) {
  s.stats = {};
  s.hints.fill(0);
  const AxisBox start = box_of_hull(g, Mat3::Identity());
  Incumbent best{g, start, start.volume()};
  face_boxes(g, s, bs, best);  // 1. flush with a hull face
  normal_arcs(g, s);           // 2. the edges' normal arcs
  FamilySearch families(g, s, best);
  families.run();              // 3. flush with two hull edges
  if (families.found()) best.box = box_of_hull(g, orthonormalize(families.axes()));
  // Polish: Bopt along the found axes can only keep or lower the volume.
  return improve(g, best.box, bs);
}

}  // namespace tightbvh::fit_detail
