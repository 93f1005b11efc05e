// A project outside the tree that uses the installed package.
#include <tightbvh/fit.hpp>
#include <tightbvh/mesh.hpp>

#include <cstdio>
#include <vector>

int main() {
  const std::vector<tightbvh::Vec3> points{{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}};
  const tightbvh::Obb box = tightbvh::fit_points(points, {.method = tightbvh::FitMethod::aabb});
  std::printf("volume %g\n", box.volume());
  return box.volume() == 6.0 ? 0 : 1;
}
