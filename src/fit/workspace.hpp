#pragma once
// Internal: the scratch buffers behind FitWorkspace (reused between calls).
#include <cstddef>
#include <vector>

#include "fitters.hpp"
#include "tightbvh/fit.hpp"
#include "tightbvh/hull.hpp"

namespace tightbvh {

struct FitWorkspace::Scratch {
  std::size_t last_hull_vertices = 0;
  ConvexHull3 hull;
  HullWorkspace hull_workspace;
  fit_detail::HullGeometry geometry;
  fit_detail::BoptScratch bopt;
  fit_detail::ExactScratch exact;
  fit_detail::Eberly2015Scratch eberly2015;
  std::vector<Vec2> polygon;
  std::vector<Vec3> distinct;  // small sets: the distinct input points (no hull computed)
  // approx-snap: the hull of the snapped points
  std::vector<Vec3> snapped;
  std::vector<std::array<std::int64_t, 3>> cells;
  ConvexHull3 snap_hull;
  fit_detail::HullGeometry snap_geometry;
  fit_detail::BoptScratch snap_bopt;
};

}  // namespace tightbvh
