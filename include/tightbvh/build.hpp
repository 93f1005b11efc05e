#pragma once
/// @file
/// The top-down builder: a pure function from a triangle soup to a Tree.
///   fit a box to the node's triangle corners -> split the triangles -> recurse on both halves.
/// Every node's box is fitted from the node's own corners, never merged from the children's
/// (merging OBBs, as FCL's operator+ does, loses tightness and even containment).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/split.hpp"
#include "tightbvh/tree.hpp"
#include "tightbvh/tree_stats.hpp"

namespace tightbvh {

/// Tight fitting where it pays, cheap fitting where it does not. The sum of box volumes sits in the
/// large nodes: on the corpus, nodes of >= 512 triangles hold 55-77% of it and nodes of < 32
/// triangles 5-8%, while the small nodes are most of the nodes. Nodes with at least
/// `tight_min_triangles` triangles get `tight` (the full search), those with at least
/// `medium_min_triangles` get `medium` (approx-kernel: the search on an O(n) extreme-point kernel),
/// the others `cheap` (normal-bopt: one Bopt along the patch's normal; small nodes are surface
/// patches, and boxes flush with them cull better in queries than their volume says). The defaults
/// are measured (docs/design-notes/auto-fitter.md, "Spend the search where the volume is").
struct AutoFit {
  std::uint32_t tight_min_triangles = 1024;     ///< Nodes with at least this many triangles get `tight`
  FitMethod tight = FitMethod::approx;          ///< The fitter of the large nodes.
  /// Nodes with at least this many triangles (and fewer than tight_min_triangles) get `medium`.
  std::uint32_t medium_min_triangles = 64;
  FitMethod medium = FitMethod::approx_kernel;  ///< The fitter of the middle-sized nodes.
  FitMethod cheap = FitMethod::normal_bopt;     ///< The fitter of the small nodes.
  bool or_aabb = true;  ///< keep the AABB instead when it is smaller (it costs one pass)
  /// `tight` nodes with more distinct vertices than this search their box orientation on the
  /// column extremes of a 64 x 64 grid (at most 8192 points; Barequet & Har-Peled 6.3 approximate
  /// the set on a grid before hulling it) and measure the extents over all vertices; 0: never.
  std::uint32_t column_extremes_above = 65536;
  /// On meshes of more than this many triangles both thresholds grow in proportion to the mesh
  /// (x n / scale_above, for example 2,356 and 147 on bunny00's 75,408 triangles, 37,704 and 2,356 on
  /// 1.2M); 0: never. A node's share of the sum of volumes follows its fraction of the mesh, not
  /// its triangle count (the pca trees of bunny00 and of bunny00 subdivided twice, 16x the
  /// triangles, hold the same shares in nodes of the same fraction), so on large meshes fixed
  /// thresholds would spend the tight search on nodes that hold little volume
  /// (docs/design-notes/auto-fitter.md, "Thresholds that grow with the mesh").
  std::uint32_t scale_above = 32768;
  /// Below the root, start each node's search from its parent's box: a child is a part of its
  /// parent, cut across the parent's box, and the parent's axes are most often close to its own
  /// best ones. `tight` (approx) nodes then run approx's axis improvement and tilt search from the
  /// best Bopt box along the parent's three axes instead of scanning the direction grid first (the
  /// root keeps the scan, and with it Barequet & Har-Peled's guarantee), `medium` (approx-kernel)
  /// nodes the kernel's axis improvement from those three Bopt boxes and three along the node's
  /// PCA axes instead of its grid scan, and `cheap` (normal-bopt) nodes keep the box along the
  /// parent's axes where the Bopt box is larger, instead of the PCA box (so they need no moments).
  /// Measured on the ten corpus meshes of the build bench, together with the thresholds above:
  /// >= 0.9 of approx's gain on all ten, with 15-30% fewer instructions than independent searches
  /// at tight_min_triangles 2048 and scale_above 131,072
  /// (docs/design-notes/auto-fitter.md, "Search from the parent's box").
  /// false: each node searches on its own.
  bool search_from_parent = true;
  /// Field-wise equality.
  friend bool operator==(const AutoFit&, const AutoFit&) = default;
};

/// The builder's choice of box fitter: a fixed method at every node, or the `auto` policy.
using Fitter = std::variant<FitMethod, AutoFit>;

/// The fitter named `name`: "auto" or any name parse_fit_method accepts; nullopt for an unknown
/// name.
[[nodiscard]] std::optional<Fitter> parse_fitter(std::string_view name);
/// The name parse_fitter() accepts for `fitter` ("auto" for any AutoFit).
[[nodiscard]] std::string to_string(const Fitter& fitter);
/// What parse_fitter accepts: "auto", then fit_method_names().
[[nodiscard]] std::vector<std::string_view> fitter_names();

/// How build() makes a tree.
struct BuildOptions {
  Fitter fitter = AutoFit{};  ///< The box fitter of every node, or the `auto` policy.
  FitOptions fit;                         ///< grid / epsilon / improve; fit.method is set per node
  SplitMethod split = SplitMethod::rapid;  ///< How a node's triangles are divided between its children.
  std::uint32_t leaf_size = 1;            ///< max triangles per leaf (RAPID and FCL use 1)
  unsigned threads = 0;                   ///< 0: std::thread::hardware_concurrency()
};

/// What build_with_stats() reports besides the tree.
struct BuildStats {
  TreeStats tree;        ///< The shape of the tree built (tree_stats()).
  double seconds = 0.0;  ///< wall-clock time of the build (not of computing these stats)
};

/// A tree and the statistics of its build.
struct BuildResult {
  Tree tree;         ///< The tree, as build() returns it.
  BuildStats stats;  ///< Its shape and the build's wall-clock time.
};

/// approx-snap runs an exact minimum box on every node's snapped hull: knot1's 6,400 triangles
/// take ~2 minutes on one core, and the time grows faster than the triangle count. Builds with it
/// are refused above this size (they would not finish in 10 minutes); `approx` is the practical
/// (1+eps) fitter for trees.
inline constexpr std::size_t kMaxApproxSnapTriangles = 20'000;

/// The tree of `mesh` (boxes in the mesh frame), built top-down as described above.
/// Pure; the result is the same bit for bit for any `threads`. Throws InputError for an invalid
/// mesh (see check_mesh), more than 2^32 - 2 triangles, leaf_size == 0, or approx-snap on more
/// than kMaxApproxSnapTriangles triangles.
[[nodiscard]] Tree build(const Mesh& mesh, const BuildOptions& options = {});
/// build(), with the tree's statistics and the build's wall-clock time. Same errors.
[[nodiscard]] BuildResult build_with_stats(const Mesh& mesh, const BuildOptions& options = {});

}  // namespace tightbvh
