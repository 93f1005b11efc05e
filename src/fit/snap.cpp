// approx-snap: ApproxMinVolBbx of Barequet & Har-Peled (Section 6.3, Fig. 6.2).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "fitters.hpp"
#include "tightbvh/hull.hpp"
#include "workspace.hpp"

namespace tightbvh::fit_detail {

// ApproxMinVolBbx (Section 6.3, Fig. 6.2): snap the hull vertices to the 8 corners of their
// cell of G = Grid(B_eps / 2), B_eps = (eps / 200) B*(S), then the exact box of the snapped hull.
Mat3 snap_axes(FitWorkspace::Scratch& s, double epsilon) {
  const AxisBox bstar = lemma_box(s.geometry, s.bopt);
  const Vec3 cell = (bstar.hi - bstar.lo) * (epsilon / 400.0);
  s.cells.clear();
  for (const Vec3& p : s.geometry.local) {
    const Vec3 q = (bstar.axes.transpose() * p - bstar.lo).cwiseQuotient(cell);
    const std::array<std::int64_t, 3> base{static_cast<std::int64_t>(std::floor(q.x())),
                                           static_cast<std::int64_t>(std::floor(q.y())),
                                           static_cast<std::int64_t>(std::floor(q.z()))};
    for (int c = 0; c < 8; ++c) s.cells.push_back({base[0] + (c & 1), base[1] + ((c >> 1) & 1), base[2] + ((c >> 2) & 1)});
  }
  std::sort(s.cells.begin(), s.cells.end());
  s.cells.erase(std::unique(s.cells.begin(), s.cells.end()), s.cells.end());
  s.snapped.clear();
  for (const auto& c : s.cells) {
    const Vec3 q = bstar.lo + Vec3(static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])).cwiseProduct(cell);
    s.snapped.push_back(bstar.axes * q);
  }
  convex_hull(s.snapped, s.snap_hull, s.hull_workspace);
  if (s.snap_hull.dimension < 3) return bstar.axes;
  s.snap_geometry.reset(s.snap_hull, Vec3::Zero());
  return exact_box(s.snap_geometry, s.exact, s.snap_bopt).axes;
}

}  // namespace tightbvh::fit_detail
