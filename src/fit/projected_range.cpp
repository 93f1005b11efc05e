#include "projected_range.hpp"

#include <algorithm>
#include <limits>

namespace tightbvh::fit_detail {

void projected_range_scalar(const double* xyz, std::size_t n, const double (&a)[3][4], double (&lo)[3],
                            double (&hi)[3]) {
  for (int j = 0; j < 3; ++j) lo[j] = std::numeric_limits<double>::infinity(), hi[j] = -lo[j];
  for (std::size_t k = 0; k < n; ++k) {
    const double x = xyz[3 * k], y = xyz[3 * k + 1], z = xyz[3 * k + 2];
    for (int j = 0; j < 3; ++j) {
      const double q = (x * a[0][j] + y * a[1][j]) + z * a[2][j];
      lo[j] = std::min(lo[j], q), hi[j] = std::max(hi[j], q);
    }
  }
}

}  // namespace tightbvh::fit_detail
