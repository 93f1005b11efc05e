#pragma once
// A 3D hull through qhull, as a test and benchmark oracle for our Quickhull (never part of the
// library): a dimension probe, an Akl-Toussaint prefilter and qhull options 'Qt Q8', then 'QJ'.
// Only for solid sets: returns false (and an empty `out`)
// when the probe finds the set flat or qhull fails.
#include <memory>
#include <span>

#include "tightbvh/hull.hpp"

namespace tightbvh::oracle {

class QhullWorkspace {
 public:
  QhullWorkspace();
  ~QhullWorkspace();
  struct State;

 private:
  friend bool qhull_hull(std::span<const Vec3>, ConvexHull3&, QhullWorkspace&, const char*);
  std::unique_ptr<State> state_;
};

// `options` replaces 'Qt Q8' when given (the 'QJ' fallback stays).
bool qhull_hull(std::span<const Vec3> points, ConvexHull3& out, QhullWorkspace& workspace,
                const char* options = nullptr);

}  // namespace tightbvh::oracle
