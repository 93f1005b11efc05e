#pragma once
/// @file
/// Refit for deforming meshes: the same triangles, moved vertices. The tree keeps its topology
/// (nodes, children, triangle_order) and every box is fitted again from the node's own triangle
/// corners, never merged from the children's boxes (merged OBBs lose tightness, see build.hpp).
#include "tightbvh/build.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// How refit() fits the boxes again.
struct RefitOptions {
  /// The fitter of every node. `pca` (the default) and `pca-vertex` take a fast path: the moments
  /// of a node are the sums of its children's, the axes come from Jacobi sweeps started at the
  /// node's previous axes, and only the one extents pass touches all of a node's corners; the
  /// boxes are the ones fit_triangles gives (up to rounding; with tied eigenvalues the previous
  /// frame's directions are kept).
  /// `aabb` merges the children's bounds (the builder's boxes bit for bit). Every other fitter
  /// (and `auto`) fits each node from its corners as build() does. Why pca:
  /// docs/design-notes/refit.md, "pca by default".
  Fitter fitter = FitMethod::pca;
  FitOptions fit;        ///< grid / epsilon / improve of the hull-based fitters
  unsigned threads = 0;  ///< 0: std::thread::hardware_concurrency(); the same tree for any count
};

/// Refits every box of `tree` to `mesh`, which must have the triangles the tree was built on (same
/// count, same index triples; only vertices moved). Single-triangle nodes get the builder's
/// closed-form triangle box. Throws InputError when the mesh is invalid (require_valid_mesh:
/// NaN/Inf vertex, index out of range), when its triangle count differs from the tree's, or when the tree's
/// structure is broken (child or leaf range out of range, a node reached twice, a triangle listed
/// twice); `tree` is left unchanged then.
void refit(Tree& tree, const Mesh& mesh, const RefitOptions& options = {});

/// The same, returning a refitted copy.
[[nodiscard]] Tree refitted(const Tree& tree, const Mesh& mesh, const RefitOptions& options = {});

}  // namespace tightbvh
