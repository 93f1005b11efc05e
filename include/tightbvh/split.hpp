#pragma once
/// @file
/// How the builder divides a node's triangles between its two children.
#include <optional>
#include <span>
#include <string_view>

namespace tightbvh {

/// How the builder divides a node's triangles between its two children.
enum class SplitMethod {
  /// RAPID (Gottschalk, Lin & Manocha 1996): cut the longest axis of the node's box at the mean
  /// of the projected triangle centroids; if a side is empty try the other two axes, then split
  /// by count. Cheap and adapts to the box's own orientation.
  rapid,
  /// Half the triangles on each side, ordered by centroid along the longest box axis
  /// (ties broken by triangle index). Balanced trees, depth ceil(log2(n / leaf_size)).
  median,
  /// Binned cost-based split: 32 bins of centroids along each box axis, minimise
  /// N_left * area(left) + N_right * area(right), areas of the children's bounds in the node's
  /// frame (a surface-area heuristic adapted to collision queries).
  binned,
};

/// The split named `name` ("rapid", "median", "binned", or "sah" for binned); nullopt for an
/// unknown name. The one table of split names (splitter.cpp).
[[nodiscard]] std::optional<SplitMethod> parse_split_method(std::string_view name);
/// The name of `method` that parse_split_method() accepts.
[[nodiscard]] std::string_view to_string(SplitMethod method);
/// Every split, in declaration order ("rapid", "median", "binned").
[[nodiscard]] std::span<const SplitMethod> all_split_methods();
[[nodiscard]] std::span<const std::string_view> split_method_names();  ///< same order

}  // namespace tightbvh
