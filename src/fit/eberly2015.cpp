// Eberly 2015 ("Minimum-Volume Box Containing a Set of Points", 2015): the predecessor of
// exact_box. It keeps the smallest of (Section 2) the boxes with a face flush with a hull face
// and (Section 3) the boxes spanned by three mutually orthogonal hull edges. It misses minima
// flush with edges only (the regular tetrahedron: Eberly 2024, eq. (1)), so it is an upper bound.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "fitters.hpp"
#include "frame.hpp"

namespace tightbvh::fit_detail {
namespace {

// |d_i . d_j| below which two unit edge directions count as orthogonal. Eberly tests exact zero
// with rational arithmetic; decimal mesh coordinates that are orthogonal keep ~1e-16 here.
constexpr double kOrthogonal = 1e-12;

bool lex_less(const Vec3& x, const Vec3& y) {
  return x.x() < y.x() || (x.x() == y.x() && (x.y() < y.y() || (x.y() == y.y() && x.z() < y.z())));
}

// The best box so far: a candidate counts with its extents over every hull vertex (box_of_hull).
struct Best {
  const HullGeometry& g;
  AxisBox box;
  double volume = std::numeric_limits<double>::infinity();

  void offer(const Mat3& axes) {
    const AxisBox checked = box_of_hull(g, orthonormalize(axes));
    if (checked.volume() < volume) volume = checked.volume(), box = checked;
  }
};

// Section 2: Bopt (the 2D rotating calipers) along each distinct hull face normal.
void face_boxes(const HullGeometry& g, Eberly2015Scratch& s, BoptScratch& bs, Best& best) {
  const auto& normals = g.hull->face_normals;
  s.directions.assign(normals.begin(), normals.end());
  std::sort(s.directions.begin(), s.directions.end(), lex_less);
  s.directions.erase(std::unique(s.directions.begin(), s.directions.end()), s.directions.end());
  for (const Vec3& n : s.directions) {
    const AxisBox candidate = bopt(g, n, bs);
    if (candidate.volume() < best.volume) best.offer(candidate.axes);
  }
  s.face_directions = s.directions.size();
}

// The distinct unit directions of the hull's true edges (flat edges inside a triangulated
// planar facet join faces with one normal and are skipped), sign-normalised so that the
// largest component is positive.
void edge_directions(const HullGeometry& g, Eberly2015Scratch& s) {
  const ConvexHull3& hull = *g.hull;
  s.directions.clear();
  for (const HullEdge& e : hull.edges) {
    if (hull.face_normals[e.face[0]] == hull.face_normals[e.face[1]]) continue;
    Vec3 d = (g.local[e.vertex[1]] - g.local[e.vertex[0]]).normalized();
    if (!d.allFinite()) continue;
    Eigen::Index k = 0;
    d.cwiseAbs().maxCoeff(&k);
    if (d[k] < 0.0) d = -d;
    s.directions.push_back(d);
  }
  std::sort(s.directions.begin(), s.directions.end(), lex_less);
  s.directions.erase(std::unique(s.directions.begin(), s.directions.end()), s.directions.end());
}

// Section 3: every triple of mutually orthogonal edge directions i < j < k. For each i the
// directions orthogonal to it are listed once (O(E^2) dot products); a triple is then a pair
// (j, k) in that list that is orthogonal too (hull edges have few orthogonal partners).
void edge_triples(Eberly2015Scratch& s, Best& best) {
  const auto& d = s.directions;
  const std::size_t n = d.size();
  for (std::size_t i = 0; i < n; ++i) {
    s.partners.clear();
    for (std::size_t j = i + 1; j < n; ++j)
      if (std::abs(d[i].dot(d[j])) <= kOrthogonal) s.partners.push_back(static_cast<std::uint32_t>(j));
    for (std::size_t a = 0; a < s.partners.size(); ++a)
      for (std::size_t b = a + 1; b < s.partners.size(); ++b) {
        const Vec3& dj = d[s.partners[a]];
        const Vec3& dk = d[s.partners[b]];
        if (!(std::abs(dj.dot(dk)) <= kOrthogonal)) continue;
        ++s.edge_triples;
        Mat3 axes;
        axes.col(0) = d[i];
        axes.col(1) = dj;
        axes.col(2) = d[i].cross(dj);  // parallel to dk (Eberly's exact-arithmetic U[2])
        best.offer(axes);
      }
  }
}

}  // namespace

AxisBox eberly2015_box(const HullGeometry& g, Eberly2015Scratch& scratch, BoptScratch& bopt_scratch) {
  scratch.face_directions = 0;
  scratch.edge_triples = 0;
  Best best{g, AxisBox{}};
  face_boxes(g, scratch, bopt_scratch, best);
  edge_directions(g, scratch);
  edge_triples(scratch, best);
  if (!std::isfinite(best.volume)) best.offer(Mat3::Identity());  // unreachable for a solid hull
  return best.box;
}

}  // namespace tightbvh::fit_detail
