#pragma once
// Internal: the hull-based fitters. Each returns axes + hull extents in the hull's local
// frame; fit.cpp turns them into an Obb over the input points.
#include <array>
#include <cstdint>
#include <vector>

#include "bopt.hpp"
#include "tightbvh/fit.hpp"

namespace tightbvh::fit_detail {

// Whether `method` starts from the set's PCA box (approx-kernel, normal-bopt): the tree builder
// then hands it the node's PCA axes, from moments it derives along the tree (build.cpp).
[[nodiscard]] bool uses_pca_axes(FitMethod method);
// fit_triangles(corners, vertices, options, workspace) with the PCA axes of the triangles
// (pca_triangle_axes(corners, vertices[0]), or the same up to rounding) given, or null (then
// computed where needed); methods that do not use them ignore them. `parent_axes` (auto's
// search_from_parent, build.hpp): approx, approx-kernel and normal-bopt start from Bopt along
// these axes (normal-bopt: its fallback box) instead of their grid scans (the PCA box).
[[nodiscard]] Obb fit_triangles_with_pca_axes(std::span<const Vec3> corners, std::span<const Vec3> vertices,
                                              const FitOptions& options, FitWorkspace& workspace, const Mat3* pca_axes,
                                              const Mat3* parent_axes = nullptr);

// B*(S) of Lemma 6.3.1: approximate diameter st, approximate diameter s't' of the projection
// onto the plane orthogonal to st, third axis orthogonal to both. O(n), volume <= 7 optimum.
// `scratch` only lends its buffer for the projection (scratch.plane).
[[nodiscard]] AxisBox lemma_box(const HullGeometry& g, BoptScratch& scratch);
// B*(S) as used in Section 6.5 (Tables 6.1/6.2): Bopt(S, {st}) along the approximate diameter
// st of lemma_box (never larger than the lemma's box, so still a 7-approximation).
[[nodiscard]] AxisBox diameter_box(const HullGeometry& g, BoptScratch& scratch);

// The primitive vectors (i1, i2, i3) with max |ij| <= k and gcd 1, one of each pair +-v.
[[nodiscard]] const std::vector<std::array<int, 3>>& primitive_grid(int k);

// A lower bound on the volume of every box with an axis along v, hence on Bopt(S, {v}):
// width_v(S) * |n_T . v| / |v|^2 for triangles T on points of S, n_T = (b - a) x (c - a):
// |n_T . v| / (2 |v|) is the area of T's projection along v, and a rectangle that contains a
// triangle has at least twice its area. The triangles are those of the 6 extreme points of S
// along the axes of B*(S). grid_search skips directions whose bound already reaches the volume
// to beat without solving Bopt: the same result, 40-70% fewer Bopt calls on tree nodes.
class VolumeBound {
 public:
  VolumeBound(const HullGeometry& g, const AxisBox& bstar);
  [[nodiscard]] double operator()(const Vec3& v) const;
  // True when no box with an axis along v can have a volume below `volume`.
  [[nodiscard]] bool excludes(const Vec3& v, double volume) const;

 private:
  const HullGeometry& g_;
  std::array<Vec3, 20> normals_;
  int count_ = 0;
};

// GridSearchMinVolBbx (Section 6.4, Fig. 6.3): Bopt(S, {v}) for every primitive direction v
// of Grid(B*(S)) (B*(S) = lemma_box, the box of Lemma 6.3.3 that Section 6.4 prescribes) with
// L-inf norm <= k, keep the smallest; then (if `improve`) the local improvement of Section 6.5
// from the four best and a pattern search over the best box's direction.
[[nodiscard]] AxisBox grid_search(const HullGeometry& g, const AxisBox& bstar, int k, bool improve,
                                  BoptScratch& scratch, std::span<const Vec3> seeds = {}, bool scan = true);

// The cheap variant used on kernels (approx-kernel): the grid scan of grid_search keeping only
// the best box, then at most 4 rounds of the axis improvement, stopping below a 0.1% gain; no
// restarts and no tilt search (those cost 3-5x more Bopt calls for the last 1-2% of volume).
// Both: Bopt along each of `seeds` competes with the scanned boxes; `scan` false skips the scan
// (the search starts from bstar and the seeds alone).
[[nodiscard]] AxisBox quick_grid_search(const HullGeometry& g, const AxisBox& bstar, int k, BoptScratch& scratch,
                                        std::span<const Vec3> seeds = {}, bool scan = true);

struct ExactStats {
  std::size_t edge_pairs = 0;       // ordered edge pairs with a non-empty orthogonal family
  std::size_t evaluations = 0;      // volume evaluations along the families
  std::size_t face_directions = 0;  // distinct face normals tried with Bopt
  std::size_t refined = 0;          // brackets refined by golden-section search
};

struct ExactScratch {
  struct Arc {
    Vec3 d;            // unit edge direction
    Vec3 a, b;         // outward normal range: n(t) = cos t a + sin t b, t in [0, alpha]
    double alpha = 0;  // dihedral turn of the normal across the edge, in [0, pi)
    std::uint32_t v0 = 0;
  };
  std::vector<Arc> arcs;
  std::vector<std::uint32_t> face_order;
  std::vector<std::pair<double, double>> intervals;
  std::array<std::uint32_t, 6> hints{};
  ExactStats stats;
};

// The minimum-volume box of the solid hull (O'Rourke 1985: two adjacent box faces are flush
// with hull edges). For every ordered pair of hull edges (e1, e2) the box faces through them
// have normals n1 on e1's normal arc and n2 = n1 x d2 / |n1 x d2| on e2's arc: a
// one-parameter family (Eberly 2024, Section 3), searched by sampling plus golden-section
// refinement. Boxes flush with a hull face are solved exactly by Bopt along each face normal.
[[nodiscard]] AxisBox exact_box(const HullGeometry& g, ExactScratch& scratch, BoptScratch& bopt_scratch);

struct Eberly2015Scratch {
  std::vector<Vec3> directions;           // distinct face normals, then edge directions
  std::vector<std::uint32_t> partners;    // the edge directions orthogonal to one of them
  std::size_t face_directions = 0;        // Bopt calls of the last fit
  std::size_t edge_triples = 0;           // mutually orthogonal edge triples of the last fit
};

// Eberly 2015 (eberly2015.cpp): the smallest of the boxes flush with a hull face (Section 2:
// Bopt along each distinct face normal) and of the boxes spanned by three mutually orthogonal
// hull edges (Section 3). Not always the minimum: it misses boxes flush with edges only (the
// regular tetrahedron's cube), which exact_box covers.
[[nodiscard]] AxisBox eberly2015_box(const HullGeometry& g, Eberly2015Scratch& scratch, BoptScratch& bopt_scratch);

// approx-snap, ApproxMinVolBbx (Section 6.3, Fig. 6.2; snap.cpp): the axes of the exact box
// of the hull vertices (s.geometry) snapped to the corners of a grid of cells (eps / 400) B*(S).
// Uses s's snap_* buffers and exact scratch.
[[nodiscard]] Mat3 snap_axes(FitWorkspace::Scratch& s, double epsilon);

}  // namespace tightbvh::fit_detail
