#pragma once
/// @file
/// Export of a tightbvh Tree into FCL: an fcl::BVHModel that holds *our* topology and *our* boxes,
/// so FCL users get tighter trees without leaving FCL (library tightbvh_fcl, needs FCL 0.7).
///
/// FCL's trees have exactly one triangle per leaf (2n-1 nodes); our leaves may hold several, so
/// each multi-triangle leaf is split further (median of centroids along its longest box axis)
/// and the new nodes' boxes are fitted by *our* fitter from the triangle corners. FCL's own
/// fit() and OBB merge are never used: they can return boxes that do not contain their input.
#include <memory>
#include <span>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/RSS.h>

#include "tightbvh/fit.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tree.hpp"

namespace tightbvh {

/// How to_fcl() and its variants export a tree.
struct FclExportOptions {
  /// Fits the boxes of the nodes created below our multi-triangle leaves. Use the fitter the
  /// tree was built with (the boxes of the tree's own nodes are exported unchanged).
  FitOptions fit = pca_fit();
  /// FitOptions with method pca and the other options at their defaults: the default of `fit`.
  [[nodiscard]] static FitOptions pca_fit() {
    FitOptions f;
    f.method = FitMethod::pca;
    return f;
  }
};

/// The FCL model of `tree` over `mesh`, with OBB boxes: vertices and triangles in the mesh's order (FCL's
/// collision results name original triangle indices), our boxes, our split structure.
/// Throws InputError if the tree does not belong to the mesh (every triangle exactly once).
/// The model's bv_fitter/bv_splitter are FCL's defaults again on return: refitting it later
/// (endUpdateModel/endReplaceModel) rebuilds FCL's own boxes.
[[nodiscard]] std::shared_ptr<fcl::BVHModel<fcl::OBB<double>>> to_fcl(const Tree& tree, const Mesh& mesh,
                                                                       const FclExportOptions& options = {});
/// The same as to_fcl() with OBBRSS volumes: each node's OBB is our box, its RSS fitted to it
/// (fit_rss). Same errors.
[[nodiscard]] std::shared_ptr<fcl::BVHModel<fcl::OBBRSS<double>>> to_fcl_obbrss(
    const Tree& tree, const Mesh& mesh, const FclExportOptions& options = {});
/// PQP's volume alone, for FCL's distance queries: each node's RSS fitted to our box (fit_rss).
[[nodiscard]] std::shared_ptr<fcl::BVHModel<fcl::RSS<double>>> to_fcl_rss(const Tree& tree, const Mesh& mesh,
                                                                          const FclExportOptions& options = {});

/// Our box as FCL's: the same box, axes reordered longest first (FCL's convention), right-handed.
[[nodiscard]] fcl::OBB<double> to_fcl_obb(const Obb& box);

/// A rectangle-swept sphere containing `points`, in the frame of `box` (which must contain
/// them): the rectangle lies in the box's mid-plane across its two longest axes; the radius is
/// the largest distance of a point to the rectangle (so containment holds by construction);
/// the rectangle is shrunk by the amount giving the smallest RSS volume among a few candidates.
/// The axes are orthonormalised first (a tree's float axes are only orthonormal to ~1e-7).
/// Throws InputError when `points` is empty.
[[nodiscard]] fcl::RSS<double> fit_rss(const Obb& box, std::span<const Vec3> points);

}  // namespace tightbvh
