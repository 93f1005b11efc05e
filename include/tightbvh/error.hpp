#pragma once
/// @file
/// The one exception type for bad input data.
#include <stdexcept>

namespace tightbvh {

/// Every error about input data (files, meshes, point sets, options, tree files): the message
/// names the source (a file, "mesh", "fit", ...) and what was wrong, and where.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tightbvh
