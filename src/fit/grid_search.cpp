// GridSearchMinVolBbx, Barequet & Har-Peled Section 6.4 (Fig. 6.3), with the local
// improvement step of Section 6.5 (the "(Improved)" rows of Tables 6.1 and 6.2).
#include <mutex>
#include <numeric>

#include "fitters.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::fit_detail {

constexpr int kMaxGrid = 64;

const std::vector<std::array<int, 3>>& primitive_grid(int k) {
  if (k < 1 || k > kMaxGrid) throw InputError("fit: grid radius k must be in [1, 64]");
  static std::array<std::once_flag, kMaxGrid + 1> once;
  static std::array<std::vector<std::array<int, 3>>, kMaxGrid + 1> tables;
  std::call_once(once[k], [k] {
    auto& t = tables[k];
    for (int i = -k; i <= k; ++i)
      for (int j = -k; j <= k; ++j)
        for (int l = -k; l <= k; ++l) {
          // One of v, -v: the first non-zero coordinate is positive.
          const int first = i != 0 ? i : (j != 0 ? j : l);
          if (first <= 0) continue;
          if (std::gcd(std::gcd(std::abs(i), std::abs(j)), std::abs(l)) != 1) continue;
          t.push_back({i, j, l});
        }
  });
  return tables[k];
}

AxisBox grid_search(const HullGeometry& g, const AxisBox& bstar, int k, bool improve_step, BoptScratch& scratch) {
  // Grid(B*(S)) is spanned by the box's edge vectors b_j = extent_j * axis_j.
  const Vec3 extent = bstar.hi - bstar.lo;
  Mat3 basis;
  for (int j = 0; j < 3; ++j) basis.col(j) = extent[j] * bstar.axes.col(j);
  AxisBox best = bstar;
  double best_volume = bstar.volume();
  for (const auto& c : primitive_grid(k)) {
    const Vec3 v = basis * Vec3(c[0], c[1], c[2]);
    if (!(v.squaredNorm() > 0.0)) continue;
    const AxisBox box = bopt(g, v, scratch);
    const double volume = box.volume();
    if (volume < best_volume) {
      best_volume = volume;
      best = box;
    }
  }
  return improve_step ? improve(g, best, scratch) : best;
}

}  // namespace tightbvh::fit_detail
