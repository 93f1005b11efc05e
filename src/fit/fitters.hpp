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

// Per direction i < lanes (lanes a multiple of 4; dx, dy, dz, lo and hi hold that many): lo[i] /
// hi[i] = min / max over the points (at least one) of (dx[i] x + dy[i] y) + dz[i] z. Four
// directions per AVX instruction where the CPU has AVX, else two per SSE2 one: the same rounded
// values either way (no FMA), so callers choose the same directions on every x86-64.
void projection_ranges(std::span<const Vec3> points, const double* dx, const double* dy, const double* dz, double* lo,
                       double* hi, std::size_t lanes);

// The primitive vectors (i1, i2, i3) with max |ij| <= k and gcd 1, one of each pair +-v.
[[nodiscard]] const std::vector<std::array<int, 3>>& primitive_grid(int k);

// Lower bounds on the volume of every box with an axis along v, hence on Bopt(S, {v}), as
// width_v(S) times a lower bound on the area of S's projection along v (the box's cross-section
// contains it):
// - `cheap`: |n_T . v| / |v| for triangles T on points of S, n_T = (b - a) x (c - a): twice the
//   area of T's projection, and a rectangle that contains a triangle has at least twice its area.
//   The triangles are those of the 6 extreme points of S along the axes of B*(S).
// - the full bound (operator()) also takes the projected area of the hull itself, ½ sum over its
//   faces of |N_f . v| / |v| (N_f: the face's area vector; every point of the projection is
//   covered by a face facing +v and one facing -v), summed over at most kAreaGroups groups of
//   faces with nearby normals (|sum over a group| <= sum of the group's |N_f . v|, so still a lower
//   bound); only for geometries with a hull.
// grid_search skips directions whose bound already reaches the volume to beat without solving
// Bopt: the same result with fewer Bopt calls.
class VolumeBound {
 public:
  static constexpr int kAreaGroups = 64;
  VolumeBound(const HullGeometry& g, const AxisBox& bstar);
  // The full bound.
  [[nodiscard]] double operator()(const Vec3& v) const;
  // The triangle bound alone: cheaper, used to order the grid scan.
  [[nodiscard]] double cheap(const Vec3& v) const;
  // The same with width_v(S) given (v . p over S, max - min).
  [[nodiscard]] double cheap(const Vec3& v, double width) const;
  // cheap() for `lanes` (even) directions (dx[i], dy[i], dz[i]) with the ranges [lo[i], hi[i]] of
  // their projections, into out[i]: two directions per SSE2 instruction (16-byte aligned arrays),
  // four per AVX instruction where the CPU has AVX and `lanes` is a multiple of 4 (grid_order.hpp;
  // the same values bit for bit).
  void cheap_lanes(const double* dx, const double* dy, const double* dz, const double* lo, const double* hi,
                   double* out, std::size_t lanes) const;
  // True when no box with an axis along v can have a volume below `volume` (full bound).
  [[nodiscard]] bool excludes(const Vec3& v, double volume) const;

 private:
  const HullGeometry& g_;
  std::array<Vec3, 20> normals_;
  int count_ = 0;
  std::array<Vec3, kAreaGroups> areas_;  // half the area vectors of groups of faces
  int area_count_ = 0;
};

// How much of the search beyond the grid scan grid_search spends: `full` (fit_points,
// fit_triangles: the local improvement from the four best grid boxes, run until it gains less than
// 1e-6, and the tilt search, on every set) or `by_size` (approx on tree nodes,
// fit_tree_node_approx): for a set of n points (n: hull vertices, or the points of a set without
// hull) the local improvement (Section 6.5) from the best grid box (n < 64) or the four best, run
// until it gains less than 1e-3 below n = 256, and the tilt search only from n = 128. The grid
// scan itself, which carries Section 6.4's (1 + eps) guarantee, is the same.
// Measured on the approx trees of the 10 meshes of tightbvh-build-bench
// (docs/design-notes/fitters.md, "Fewer extras on small tree nodes"): nodes below these sizes are
// most of a tree (85-90% have fewer than 16 points) but a few percent of its sum of volumes, the
// extra starts and tilts change their boxes by little (the tilts never do below 8 points), and with
// them on every node they are ~75% of a tree's Bopt calls. Against two starts from 16 points, tilts
// from 32 and a 1e-6 stop at every size, these thresholds (one start up to 63 points, tilts from
// 128, a 1e-3 stop below 256) save 19% of knot1's instructions and move the trees' sums of volumes
// by -0.2% to +0.55%; tilts from 256, four starts from 128 or the tilts' last step at 0.02 would
// move elephant's by +1.1% to +1.6%.
enum class Extras { full, by_size };
inline constexpr std::size_t kFourStartsFrom = 64;
inline constexpr std::size_t kTiltFrom = 128;
inline constexpr std::size_t kFineImprovementFrom = 256;
inline constexpr double kCoarseImprovementGain = 1e-3;
[[nodiscard]] int improvement_starts(std::size_t n, Extras extras);

// The scan's cost on tree nodes (measured on the approx trees of the 10 build-bench meshes,
// docs/design-notes/fitters.md, "Skipping directions by a volume lower bound"), without changing
// what it returns (Section 6.4's minimum over the grid):
// - Its ordering pass (the projection ranges and cheap bounds of the 49 directions) takes AVX lanes
//   where the CPU has them (grid_order.hpp; the same values bit for bit as the SSE2 loops, so the
//   same order on every x86-64), and the directions are picked in order of their bound one at a
//   time (the scan stops after a few), not sorted.
// - On sets without hull the full bound is not evaluated before Bopt: it equals the cheap bound
//   that was just tested (VolumeBound: no faces to add).
// - Bopt on hull-free sets of at most 6 points (bopt.cpp, kPairSearchMax) takes its rectangle from
//   the pair search of min_area_rect_of_points instead of the 2D hull and the calipers. Bopt of
//   Section 6.3 needs the minimum-area rectangle of the projection; one of its sides is flush with
//   a hull edge (Freeman & Shapira), every pair direction gives a rectangle containing the
//   projection, so the least over the pairs is that minimum (up to rounding and ties: the trees'
//   sums of volumes moved by at most 0.0012%), and up to 15 pairs in AVX lanes cost less than the
//   sort.
// GridSearchMinVolBbx (Section 6.4, Fig. 6.3): Bopt(S, {v}) for every primitive direction v
// of Grid(B*(S)) (B*(S) = lemma_box, the box of Lemma 6.3.3 that Section 6.4 prescribes) with
// L-inf norm <= k, keep the smallest (its (1 + eps) guarantee); then (if `improve`) the local
// improvement of Section 6.5 from the improvement_starts best and a pattern search over the best
// box's direction (with Extras::by_size from kTiltFrom points).
[[nodiscard]] AxisBox grid_search(const HullGeometry& g, const AxisBox& bstar, int k, bool improve,
                                  BoptScratch& scratch, std::span<const Vec3> seeds = {}, bool scan = true,
                                  Extras extras = Extras::full);

// approx on a tree node (the builder and refit): fit_triangles(corners, vertices, options,
// workspace) with options.method == approx and grid_search's Extras::by_size.
[[nodiscard]] Obb fit_tree_node_approx(std::span<const Vec3> corners, std::span<const Vec3> vertices,
                                       const FitOptions& options, FitWorkspace& workspace);

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
