#pragma once
/// @file
/// Versioned binary save/load of a Tree.
///
/// Layout (all integers and floats little-endian):
///   0  magic   "TBVHTREE"                                         8 bytes
///   8  version u32 (kTreeFormatVersion)
///  12  node_size u32 (68: bytes of one serialized node)
///  16  node_count u64
///  24  triangle_count u64                                         (entries of triangle_order)
///  32  checksum u64: FNV-1a 64 of bytes [16, 32) and of the payload
///  40  payload: node_count nodes {center[3], axes[9] column-major, half_extents[3] (f32),
///               first, count (u32)}, then triangle_count u32
/// The file size must be exactly 40 + node_count * 68 + triangle_count * 4, so a corrupt
/// count can never cause an allocation larger than the file.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "tightbvh/tree.hpp"

namespace tightbvh {

/// The version save_tree() writes and load_tree() reads. Version 2: float boxes (compact_box.hpp).
/// Version 1 files (double boxes) are refused with a message saying to rebuild.
inline constexpr std::uint32_t kTreeFormatVersion = 2;

/// The bytes of `tree` in the layout above (what save_tree() writes).
[[nodiscard]] std::vector<std::byte> serialize(const Tree& tree);

/// The tree stored in `bytes` (the layout above), checked: its structure is sound
/// (check_structure). Throws InputError naming `source` and the problem (wrong magic,
/// unsupported version, truncated/oversized, checksum mismatch, broken structure) for any bad
/// input.
[[nodiscard]] Tree deserialize(std::span<const std::byte> bytes, const std::string& source = "tree");

/// Writes serialize(tree) to `path`. Throws InputError naming the file if it cannot be written.
void save_tree(const Tree& tree, const std::filesystem::path& path);
/// Reads a tree written by save_tree(). Throws InputError naming the file if it cannot be read or
/// is not a valid tree (as deserialize()).
[[nodiscard]] Tree load_tree(const std::filesystem::path& path);

/// Writes serialize(tree) to `out` (the bytes of save_tree's file: an in-memory form for
/// pickling, sockets or archives). Throws InputError naming `destination` if the write fails.
void save_tree(const Tree& tree, std::ostream& out, const std::string& destination = "stream");
/// Reads `in` to its end and deserializes it (the file form reads through this). The buffer grows
/// with the bytes actually read, never with a count the header claims. Throws InputError naming
/// `source` for a read error or any input deserialize() refuses.
[[nodiscard]] Tree load_tree(std::istream& in, const std::string& source = "stream");

}  // namespace tightbvh
