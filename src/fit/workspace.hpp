#pragma once
// Internal: the scratch buffers behind FitWorkspace (reused between calls).
#include <cstddef>
#include <vector>

#include "tightbvh/fit.hpp"

namespace tightbvh {

struct FitWorkspace::Scratch {
  std::size_t last_hull_vertices = 0;
};

}  // namespace tightbvh
