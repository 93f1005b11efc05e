#pragma once
/// @file
/// A rigid pose as text: "r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz" (row-major rotation, then
/// translation), the form of `tightbvh collide --pose` and of tightbvh-bench's pose files.
#include <string_view>

#include "tightbvh/mesh.hpp"  // InputError
#include "tightbvh/pose.hpp"

namespace tightbvh {

/// Twelve finite numbers forming a proper rotation (orthonormal within 1e-6, determinant +1).
/// Throws InputError whose message has no location, so that callers can prefix theirs:
/// "not a number: 'x'", "not finite: 'x'", "expected 12 numbers (...), got N",
/// "rotation is not orthonormal (max |R^T R - I| = e)", "rotation has determinant -1 (a reflection)".
[[nodiscard]] Pose parse_pose(std::string_view text);

}  // namespace tightbvh
