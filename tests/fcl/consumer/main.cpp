// A project outside the tree that exports a tree into FCL through the installed package.
#include <tightbvh/build.hpp>
#include <tightbvh/fcl/export.hpp>

#include <cstdio>

int main() {
  const tightbvh::Mesh tetrahedron{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                   {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};
  tightbvh::BuildOptions options;
  options.fitter = tightbvh::FitMethod::aabb;
  const auto model = tightbvh::to_fcl(tightbvh::build(tetrahedron, options), tetrahedron);
  std::printf("FCL nodes %d\n", model->getNumBVs());
  return model->getNumBVs() == 7 ? 0 : 1;
}
