#pragma once
/// @file
/// The boxes of one tree level as an OBJ wireframe, for looking at a tree in any mesh viewer.
#include <cstddef>
#include <filesystem>
#include <ostream>

#include "tightbvh/tree.hpp"

namespace tightbvh {

/// Per box at depth `level` (root: 0), in preorder: its 8 corners as `v` lines (Obb::corners
/// order) and its 12 edges as `l` lines; a comment line first. Returns the number of boxes.
std::size_t write_boxes_obj(const Tree& tree, std::size_t level, std::ostream& out);

/// The same into a file; throws InputError when it cannot be written.
std::size_t write_boxes_obj(const Tree& tree, std::size_t level, const std::filesystem::path& path);

}  // namespace tightbvh
