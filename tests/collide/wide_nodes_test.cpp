// The wide nodes' float box kernel (src/collide/wide_nodes.hpp) is conservative: it never culls
// two boxes that share a point (random boxes built around a shared point, touching exactly on
// faces, edges and corners, at scales 1e-3 to 1e4 and offsets up to 1e6), nor any node pair of a
// real tree that the double test obb_overlap() keeps; and it is not much more conservative than
// needed (boxes that the double test separates by a small relative gap are culled). Also the
// wide tree's structure (every triangle once, refs as the descent computes them) and its memory;
// and the eight-lane AVX2 kernel, the portable lanes and the kernel for a signed-permutation M
// (contains()' rays) decide as the four-lane one. The float
// distance bound (wide_distance_bounds) never exceeds the boxes' exact distance (measured between
// their faces' triangles), is 0 for boxes that share a point, and is close to the double bound;
// the point bound of the closest-point search likewise against a point's exact distance to a box.
#include "collide/wide_nodes.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "collide/box_bounds4.hpp"
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "query_fixtures.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/obb_distance.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tri_distance.hpp"

namespace tightbvh {
namespace {

using namespace query_detail;

using query_test::random_rotation;

// A box of scale `s` with random axes (or `axes`) that contains `p`: p's coordinates in the box
// are random, or (each with probability 1/2) exactly +-e_i, so that p lies on a face, an edge or
// a corner.
Obb box_around(std::mt19937_64& rng, const Vec3& p, double s, const Mat3& axes) {
  std::uniform_real_distribution<double> size(0.02, 1.0), unit(-1.0, 1.0);
  std::bernoulli_distribution on_face(0.5);
  Obb b;
  b.axes = axes;
  for (int i = 0; i < 3; ++i) b.half_extents[i] = s * size(rng);
  if (on_face(rng)) b.half_extents[0] *= 1e-3;  // flat boxes too
  Vec3 local;
  for (int i = 0; i < 3; ++i) {
    const double side = unit(rng) < 0 ? -1.0 : 1.0;
    local[i] = on_face(rng) ? side * b.half_extents[i] : unit(rng) * b.half_extents[i];
  }
  b.center = p - axes * local;
  return b;
}

// B's box given in A's (world) frame, expressed in B's mesh frame under `rel` (x_A = R0 x_B + t0).
Obb to_b_frame(const Obb& world, const Pose& rel) {
  const Pose inv = rel.inverse();
  return {inv.apply(world.center), inv.rotation * world.axes, world.half_extents};
}

// The kernel on A's box `a` (world frame, node ref `ref_a`) against B's box `b` (B's mesh frame,
// in lane 0 of a node whose ref is `ref_b`; the other lanes hold `others` or stay empty). Returns
// the kept mask.
// A node of empty lanes, and `box` (relative to `ref`) put in lane `lane` of one; `eta` as widen_box.
WideNode empty_node() {
  WideNode node{};
  for (int lane = 0; lane < kWideLanes; ++lane) {
    for (int r = 0; r < 9; ++r) node.axes[r][lane] = r % 4 == 0 ? 1.0f : 0.0f;
    for (int k = 0; k < 3; ++k) {
      node.center[k][lane] = 0.0f;
      node.half[k][lane] = kEmptyHalf;
    }
  }
  return node;
}
void put_lane(WideNode& node, int lane, const Obb& box, const Vec3& ref, double& eta) {
  const WideBox wb = widen_box(box, ref, eta);
  for (int r = 0; r < 9; ++r) node.axes[r][lane] = wb.axes[r];
  for (int k = 0; k < 3; ++k) {
    node.center[k][lane] = wb.center[k];
    node.half[k][lane] = wb.half[k];
  }
}
WideNode lane0_node(const Obb& b, const Vec3& ref_b, double& eta) {
  WideNode node = empty_node();
  put_lane(node, 0, b, ref_b, eta);
  return node;
}

template <WideTier kTier = WideTier::full>
unsigned kernel(const Obb& a, const Vec3& ref_a, const Obb& b, const Vec3& ref_b, const Pose& rel,
                const std::vector<Obb>& others = {}, double margin = 0.0) {
  double eta_a = 0.0, eta_b = 0.0;
  const WideBox wa = widen_box(a, ref_a, eta_a);
  WideNode node = lane0_node(b, ref_b, eta_b);
  for (std::size_t i = 0; i < others.size() && i + 1 < kWideLanes; ++i)
    put_lane(node, static_cast<int>(i) + 1, others[i], ref_b, eta_b);
  const WideFrame f = wide_frame(rel, eta_a, eta_b, margin);
  const WideHoisted h = hoist(f, wide_pair(f, ref_a, ref_b), wa);
  const unsigned kept = wide_overlap<kTier>(h, node);
  EXPECT_EQ((wide_overlap<kTier, P4>(h, node)), kept) << "portable lanes";
  return kept;
}

// The swapped kernel (B's box hoisted in wide_frame_swapped, A's box in lane 0 of a node whose
// ref is `ref_a`), as the descent runs it: the pair's t_err grown by swap_error.
template <WideTier kTier = WideTier::full>
unsigned kernel_swapped(const Obb& a, const Vec3& ref_a, const Obb& b, const Vec3& ref_b, const Pose& rel) {
  double eta_a = 0.0, eta_b = 0.0;
  const WideBox wb = widen_box(b, ref_b, eta_b);
  const WideNode node = lane0_node(a, ref_a, eta_a);
  const WideFrame fs = wide_frame_swapped(rel, eta_a, eta_b, 0.0);
  WidePair p = wide_pair(fs, ref_b, ref_a);
  p.t_err = static_cast<float>((static_cast<double>(p.t_err) + swap_error(fs, ref_b, wb)) * (1.0 + 0x1p-20));
  const WideHoisted h = hoist(fs, p, wb);
  const unsigned kept = wide_overlap<kTier>(h, node);
  EXPECT_EQ((wide_overlap<kTier, P4>(h, node)), kept) << "portable lanes";
  return kept;
}

// The distance bound of A's box against B's (B's mesh frame under rel), forward (A hoisted) and
// swapped (B hoisted, as distance_wide runs it); each checked against the portable lanes and,
// where the CPU has AVX2, the eight-lane kernel.
struct TwoBounds {
  float forward, swapped;
};
TwoBounds distance_bounds(const Obb& a, const Vec3& ref_a, const Obb& b, const Vec3& ref_b, const Pose& rel) {
  double eta_a = 0.0, eta_b = 0.0;
  const WideNode node_b = lane0_node(b, ref_b, eta_b);
  const WideNode node_a = lane0_node(a, ref_a, eta_a);
  const WideBox box_a = lane_box(node_a, 0), box_b = lane_box(node_b, 0);
  const WideFrames frames = wide_frames(rel, eta_a, eta_b, 0.0);
  const WideHoisted hf = hoist(frames.forward, wide_pair(frames.forward, ref_a, ref_b), box_a);
  WidePair ps = wide_pair(frames.swapped, ref_b, ref_a);
  ps.t_err = static_cast<float>((static_cast<double>(ps.t_err) + swap_error(frames.swapped, ref_b, box_b)) *
                                (1.0 + 0x1p-20));
  const WideHoisted hs = hoist(frames.swapped, ps, box_b);
  float f[kWideLanes], g[kWideLanes], fp[kWideLanes];
  wide_distance_bounds(hf, node_b, wide_bound_constants(frames.forward), f);
  wide_distance_bounds(hs, node_a, wide_bound_constants(frames.swapped), g);
  wide_distance_bounds<P4>(hf, node_b, wide_bound_constants(frames.forward), fp);
  EXPECT_EQ(fp[0], f[0]) << "portable lanes";
#ifdef TIGHTBVH_WIDE_AVX2
  if (avx2_bounds_available()) {
    const WideBoundConstants c = wide_bound_constants(frames.forward);
    float eight[2 * kWideLanes];
    wide_distance_bounds2_avx2(hf, node_b, hf, node_b, c.len_sq, c.factor, eight);
    EXPECT_EQ(eight[0], f[0]) << "eight lanes";
    EXPECT_EQ(eight[4], f[0]) << "eight lanes";
  }
#endif
  for (int l = 1; l < kWideLanes; ++l) EXPECT_GT(f[l], 1e20f) << "empty lane " << l;
  return {f[0], g[0]};
}

// The exact distance between two boxes (in one frame): the least distance between their faces'
// triangles (0 if they intersect or one holds the other, which the callers exclude).
double box_distance(const Obb& a, const Obb& b) {
  const auto corners = [](const Obb& o) {
    std::vector<Vec3> c;
    for (int k = 0; k < 8; ++k)
      c.push_back(o.center + o.axes * Vec3((k & 1 ? 1 : -1) * o.half_extents[0], (k & 2 ? 1 : -1) * o.half_extents[1],
                                           (k & 4 ? 1 : -1) * o.half_extents[2]));
    return c;
  };
  // The 12 triangles of a box's faces, by corner index.
  static const int kFaces[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                    {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 3, 7}, {1, 7, 5}};
  const std::vector<Vec3> ca = corners(a), cb = corners(b);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& fa : kFaces)
    for (const auto& fb : kFaces)
      best = std::min(
          best, tri_tri_distance(ca[fa[0]], ca[fa[1]], ca[fa[2]], cb[fb[0]], cb[fb[1]], cb[fb[2]]).distance);
  return best;
}

// The distance bound: 0 for boxes that share a point (the pairs of NeverCullsBoxesThatShareAPoint's
// kind), never above the exact distance of separated boxes at scales 1e-3 to 1e4 and offsets up
// to 1e6, and at the origin within a few percent of the double bound (obb_distance_lower_bound).
TEST(WideNodes, DistanceBoundIsALowerBound) {
  std::mt19937_64 rng(381);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap(0.0, 0.5);
  int sharing = 0, separated = 0, close_to_double = 0, compared = 0;
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const double offset : {0.0, 1e3, 1e6})
      for (int n = 0; n < 150; ++n) {
        const Vec3 p = offset * Vec3(unit(rng), unit(rng), unit(rng)) + scale * Vec3(unit(rng), unit(rng), unit(rng));
        const Mat3 ra = n % 4 == 1 ? Mat3::Identity() : random_rotation(rng);
        const Mat3 rb = n % 4 == 0 ? ra : n % 4 == 1 ? Mat3::Identity() : random_rotation(rng);
        const Obb a = box_around(rng, p, scale, ra);
        Obb b_world = box_around(rng, p, scale, rb);
        const Pose rel{random_rotation(rng), offset * Vec3(unit(rng), unit(rng), unit(rng))};
        const TwoBounds touching = distance_bounds(a, a.center, to_b_frame(b_world, rel), b_world.center, rel);
        ++sharing;
        EXPECT_EQ(touching.forward, 0.0f) << "scale " << scale << " offset " << offset << " n " << n;
        EXPECT_EQ(touching.swapped, 0.0f) << "scale " << scale << " offset " << offset << " n " << n;
        // B moved away from A by up to half the scale in a random direction.
        b_world.center += scale * gap(rng) * Vec3(unit(rng), unit(rng), unit(rng)).normalized();
        const double exact = box_distance(a, b_world);
        if (!(exact > 0.0)) continue;
        ++separated;
        const Obb b = to_b_frame(b_world, rel);
        const TwoBounds apart = distance_bounds(a, a.center, b, b.center + scale * Vec3(0.1, -0.2, 0.3), rel);
        // The exact distance is measured in double from the same corners: allow its rounding.
        const double allowed = exact + 1e-12 * (scale + offset);
        EXPECT_LE(apart.forward, allowed) << "scale " << scale << " offset " << offset << " n " << n;
        EXPECT_LE(apart.swapped, allowed) << "scale " << scale << " offset " << offset << " n " << n;
        if (offset == 0.0) {
          ++compared;
          const double reference = obb_distance_lower_bound(a, b_world);
          close_to_double += apart.forward >= 0.97 * reference - 1e-5 * scale;
        }
      }
  std::printf("[ wide     ] distance bound: %d sharing pairs, %d separated, %d of %d within 3%% of the double bound\n",
              sharing, separated, close_to_double, compared);
  EXPECT_GE(separated, 500);
  EXPECT_GE(close_to_double, compared * 95 / 100);
}

// Random pairs of boxes around a shared point at each scale and offset; returns the number of
// pairs either tier culled (must be 0).
TEST(WideNodes, NeverCullsBoxesThatShareAPoint) {
  std::mt19937_64 rng(38);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::bernoulli_distribution coin(0.5);
  int pairs = 0, culled = 0;
  for (const double scale : {1e-3, 1e-1, 1.0, 1e2, 1e4})
    for (const double offset : {0.0, 1e3, 1e6})
      for (int n = 0; n < 400; ++n) {
        const Vec3 p = offset * Vec3(unit(rng), unit(rng), unit(rng)) + scale * Vec3(unit(rng), unit(rng), unit(rng));
        // A quarter share their axes (exactly touching faces of aligned boxes), a quarter are
        // axis-aligned, the rest random.
        const int kind = n % 4;
        const Mat3 ra = kind == 1 ? Mat3::Identity() : random_rotation(rng);
        const Mat3 rb = kind == 0 ? ra : kind == 1 ? Mat3::Identity() : random_rotation(rng);
        const Obb a = box_around(rng, p, scale, ra);
        const Obb b_world = box_around(rng, p, scale, rb);
        // B's mesh frame: a random pose far from the origin, or the identity.
        Pose rel;
        if (coin(rng)) rel = {random_rotation(rng), offset * Vec3(unit(rng), unit(rng), unit(rng))};
        const Obb b = to_b_frame(b_world, rel);
        // Node refs near the boxes (so offsets are of the boxes' scale), or the box centers.
        const Vec3 ref_a = a.center + (coin(rng) ? Vec3(scale * Vec3(unit(rng), unit(rng), unit(rng))) : Vec3(Vec3::Zero()));
        const Vec3 ref_b = b.center + (coin(rng) ? Vec3(scale * Vec3(unit(rng), unit(rng), unit(rng))) : Vec3(Vec3::Zero()));
        ++pairs;
        const bool full = (kernel(a, ref_a, b, ref_b, rel) & 1u) != 0;
        const bool faces = (kernel<WideTier::faces>(a, ref_a, b, ref_b, rel) & 1u) != 0;
        const bool swapped = (kernel_swapped(a, ref_a, b, ref_b, rel) & 1u) != 0;
        const bool swapped_faces = (kernel_swapped<WideTier::faces>(a, ref_a, b, ref_b, rel) & 1u) != 0;
        if (!full || !faces || !swapped || !swapped_faces) {
          ++culled;
          ADD_FAILURE() << "culled a touching pair: scale " << scale << " offset " << offset << " kind " << kind
                        << (full && faces ? " (swapped kernel)" : "");
          if (culled > 5) return;
        }
      }
  EXPECT_EQ(culled, 0) << pairs << " pairs";
}

// Boxes that the double test separates by more than 1e-4 of their scale: the float kernel culls
// (nearly) all of them. The pairs start touching and B is then moved by up to 1e-2 of the scale,
// so most gaps are small: a bound a hundred times too loose would keep many of them.
TEST(WideNodes, CullsBoxesSeparatedByASmallGap) {
  std::mt19937_64 rng(380);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int separated = 0, culled = 0, culled_swapped = 0;
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const double offset : {0.0, 1e6})
      for (int n = 0; n < 800; ++n) {
        if (offset > 1.0 && scale < 1e-2) continue;  // float's resolution at 1e6 is ~0.06
        const Vec3 p = offset * Vec3(unit(rng), unit(rng), unit(rng));
        const Obb a = box_around(rng, p, scale, random_rotation(rng));
        Obb b_world = box_around(rng, p, scale, random_rotation(rng));
        b_world.center += 1e-2 * scale * Vec3(unit(rng), unit(rng), unit(rng));
        if (obb_overlap(a, b_world, 1e-4 * scale)) continue;
        const Pose rel{random_rotation(rng), offset * Vec3(unit(rng), unit(rng), unit(rng))};
        const Obb b = to_b_frame(b_world, rel);
        ++separated;
        culled += (kernel(a, a.center, b, b.center, rel) & 1u) == 0;
        culled_swapped += (kernel_swapped(a, a.center, b, b.center, rel) & 1u) == 0;
      }
  std::printf("[ wide     ] separated by > 1e-4 of the size: %d pairs, %d culled\n", separated, culled);
  ASSERT_GT(separated, 400);
  EXPECT_GE(culled, separated * 99 / 100) << culled << " of " << separated;
  EXPECT_GE(culled_swapped, separated * 99 / 100) << culled_swapped << " of " << separated << " (swapped kernel)";
}

TEST(WideNodes, EmptyLanesAndOtherLanes) {
  std::mt19937_64 rng(7);
  const Obb a{Vec3::Zero(), Mat3::Identity(), Vec3(1, 1, 1)};
  const Obb touching{Vec3(2, 0, 0), Mat3::Identity(), Vec3(1, 1, 1)};
  const Obb far{Vec3(5, 0, 0), random_rotation(rng), Vec3(1, 1, 1)};
  const Obb inside{Vec3(0.5, 0, 0), random_rotation(rng), Vec3(0.1, 0.2, 0.3)};
  // Lane 0 touching, 1 far, 2 inside, 3 empty.
  EXPECT_EQ(kernel(a, Vec3::Zero(), touching, Vec3(1, 1, 1), Pose::identity(), {far, inside}), 0b0101u);
  EXPECT_EQ(kernel<WideTier::faces>(a, Vec3::Zero(), touching, Vec3(1, 1, 1), Pose::identity(), {far, inside}),
            0b0101u);
  // The far box is between 5 - 1 - sqrt(3) and 5 - 1 - 1 away from A along x: a margin of 1 culls
  // it, one of 3.5 keeps it.
  EXPECT_EQ(kernel(a, Vec3::Zero(), far, Vec3::Zero(), Pose::identity(), {}, 1.0) & 1u, 0u);
  EXPECT_EQ(kernel(a, Vec3::Zero(), far, Vec3::Zero(), Pose::identity(), {}, 3.5) & 1u, 1u);
}

TEST(WideNodes, BothFramesAtOnceEqualTheTwoCalls) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> coord(-1e3, 1e3);
  const auto same = [](const WideFrame& x, const WideFrame& y) {
    for (int r = 0; r < 9; ++r) EXPECT_EQ(x.r0[r], y.r0[r]);
    EXPECT_EQ(x.r0_d, y.r0_d);
    EXPECT_EQ(x.t0_d, y.t0_d);
    EXPECT_EQ(x.kappa, y.kappa);
    EXPECT_EQ(x.margin, y.margin);
    EXPECT_EQ(x.swap_rel, y.swap_rel);
    EXPECT_EQ(x.swap_abs, y.swap_abs);
  };
  for (int i = 0; i < 20; ++i) {
    const Pose rel{random_rotation(rng), Vec3(coord(rng), coord(rng), coord(rng))};
    const double eta_a = 1e-7 * (i % 3), eta_b = 2e-7 * (i % 2), margin = 0.01 * i;
    const WideFrames both = wide_frames(rel, eta_a, eta_b, margin);
    same(both.forward, wide_frame(rel, eta_a, eta_b, margin));
    same(both.swapped, wide_frame_swapped(rel, eta_a, eta_b, margin));
    EXPECT_GT(both.swapped.swap_rel, 0.0);
  }
  EXPECT_THROW((void)wide_frames(Pose::identity(), 0.0, 0.0, -1.0), InputError);
}

TEST(WideNodes, RejectsBadInput) {
  double eta = 0.0;
  Obb bad{Vec3(std::nan(""), 0, 0), Mat3::Identity(), Vec3(1, 1, 1)};
  EXPECT_THROW((void)widen_box(bad, Vec3::Zero(), eta), InputError);
  Obb sheared{Vec3::Zero(), Mat3::Identity(), Vec3(1, 1, 1)};
  sheared.axes(0, 1) = 0.1;
  EXPECT_THROW((void)widen_box(sheared, Vec3::Zero(), eta), InputError);
  EXPECT_THROW((void)wide_frame(Pose::identity(), 0.0, 0.0, -1.0), InputError);
}

Mesh shipped_mesh(const char* name) { return load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/" + name); }

// Every triangle in exactly one leaf lane; refs and sources consistent; memory per triangle.
TEST(WideNodes, TreeStructureAndMemory) {
  for (const char* name : {"knot1.off", "fandisk.off"}) {
    const Mesh mesh = shipped_mesh(name);
    const Tree tree = build(mesh);
    std::vector<std::uint32_t> sources;
    const WideTree wide = build_wide(tree, &sources);
    ASSERT_EQ(sources.size(), 4 * wide.nodes.size());
    std::vector<int> seen(mesh.triangles.size(), 0);
    std::size_t internal = 0;
    for (std::size_t i = 0; i < wide.nodes.size(); ++i)
      for (int lane = 0; lane < kWideLanes; ++lane) {
        const WideNode& n = wide.nodes[i];
        if (is_empty_lane(n, lane)) continue;
        const Node& src = tree.nodes[sources[4 * i + lane]];
        if (n.child[lane] < 0) {
          const WideTree::LeafRange leaf = wide.leaf(n.child[lane]);
          EXPECT_EQ(leaf.first, src.first);
          EXPECT_EQ(leaf.count, src.count);
          for (std::uint32_t k = 0; k < leaf.count; ++k) ++seen[tree.triangle_order[leaf.first + k]];
        } else {
          ASSERT_GT(n.child[lane], 0);
          ++internal;
        }
      }
    EXPECT_EQ(internal + 1, wide.nodes.size());
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
    EXPECT_LT(wide.eta, 1e-6);
    const double bytes = wide_bytes_per_triangle(wide, mesh.triangles.size());
    std::printf("[ wide     ] %s: %zu triangles, %zu wide nodes of %zu B, %.1f B/triangle, eta %.2g\n", name,
                mesh.triangles.size(), wide.nodes.size(), sizeof(WideNode), bytes, wide.eta);
    EXPECT_LE(bytes, 150.0) << name;
  }
}

// Real nodes: two trees over shipped meshes in random poses that make them overlap; a descent
// over wide node pairs tests each box of A against the four children of a node of B with the
// float kernel, and every lane the double test (obb_overlap of the Tree's boxes, margin 0) keeps
// must be kept.
TEST(WideNodes, KeepsEveryRealNodePairTheDoubleTestKeeps) {
  std::mt19937_64 rng(3800);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::size_t tested = 0, kept_double = 0, kept_float = 0, missed = 0, lanes_differ = 0, portable_differ = 0;
  std::size_t kept_swapped = 0, missed_swapped = 0;
  const bool avx2 = avx2_bounds_available();
  struct Item {
    std::int32_t na;
    int lane;
    std::int32_t nb;
    Vec3 ref_a, ref_b;
  };
  for (const double offset : {0.0, 1e5}) {
    // Both meshes moved far from the origin (in their own frames) for the second round.
    Mesh ma = shipped_mesh("knot1.off"), mb = shipped_mesh("fandisk.off");
    const Vec3 shift_a = offset * Vec3(unit(rng), unit(rng), unit(rng)),
               shift_b = offset * Vec3(unit(rng), unit(rng), unit(rng));
    for (Vec3& v : ma.vertices) v += shift_a;
    for (Vec3& v : mb.vertices) v += shift_b;
    const Tree ta = build(ma), tb = build(mb);
    std::vector<std::uint32_t> sa, sb;
    const WideTree wa = build_wide(ta, &sa), wb = build_wide(tb, &sb);
    const Obb box_a = ta.nodes[0].box.obb(), box_b = tb.nodes[0].box.obb();
    const double size = std::max(box_a.half_extents.norm(), box_b.half_extents.norm());
    for (int pose = 0; pose < 3; ++pose) {
      // B's root center near A's root center.
      const Mat3 rot = random_rotation(rng);
      const Pose rel{rot, box_a.center - rot * box_b.center + 0.3 * size * Vec3(unit(rng), unit(rng), unit(rng))};
      const WideFrame f = wide_frame(rel, wa.eta, wb.eta, 0.0);
      const WideFrame fs = wide_frame_swapped(rel, wa.eta, wb.eta, 0.0);
      std::vector<Item> stack;
      for (int lane = 0; lane < kWideLanes; ++lane)
        if (!is_empty_lane(wa.nodes[0], lane)) stack.push_back({0, lane, 0, wa.root_ref, wb.root_ref});
      std::size_t budget = 60000;
      while (!stack.empty() && budget-- > 0) {
        const Item it = stack.back();
        stack.pop_back();
        const WideNode& na = wa.nodes[it.na];
        const WideNode& nb = wb.nodes[it.nb];
        const WideHoisted h = hoist(f, wide_pair(f, it.ref_a, it.ref_b), lane_box(na, it.lane));
        const unsigned kept = wide_overlap(h, nb);
        // The eight-lane AVX2 kernel (where the CPU has it) and the portable lanes decide each
        // lane alike.
        const WideNode& other = wb.nodes[(it.nb + 1) % wb.nodes.size()];
        if (wide_overlap2(h, nb, h, other, avx2) != (kept | wide_overlap(h, other) << 4)) ++lanes_differ;
        if (wide_overlap<WideTier::full, P4>(h, nb) != kept) ++portable_differ;
        if (wide_overlap<WideTier::faces, P4>(h, nb) != wide_overlap<WideTier::faces>(h, nb)) ++portable_differ;
        const Obb a_box = ta.nodes[sa[4 * it.na + it.lane]].box.obb();
        for (int j = 0; j < kWideLanes; ++j) {
          if (is_empty_lane(nb, j)) {
            EXPECT_EQ(kept >> j & 1u, 0u);
            continue;
          }
          const Obb b = tb.nodes[sb[4 * it.nb + j]].box.obb();
          const Obb b_in_a{rel.apply(b.center), rel.rotation * b.axes, b.half_extents};
          const bool d = obb_overlap(a_box, b_in_a);
          const bool fl = (kept >> j & 1u) != 0;
          // The swapped kernel: B's box j hoisted against A's node, read at A's lane.
          WidePair ps = wide_pair(fs, it.ref_b, it.ref_a);
          const WideBox bj = lane_box(nb, j);
          ps.t_err = static_cast<float>((static_cast<double>(ps.t_err) + swap_error(fs, it.ref_b, bj)) * (1.0 + 0x1p-20));
          const bool sw = (wide_overlap(hoist(fs, ps, bj), na) >> it.lane & 1u) != 0;
          kept_swapped += sw;
          if (d && !sw && ++missed_swapped <= 5)
            ADD_FAILURE() << "pose " << pose << ": a pair the double test keeps was culled by the swapped kernel";
          ++tested;
          kept_double += d;
          kept_float += fl;
          if (d && !fl && ++missed <= 5)
            ADD_FAILURE() << "pose " << pose << ": a pair the double test keeps was culled";
          if (!fl) continue;
          // Descend: B's child j against A's box, and A's children against B's child j.
          const bool a_internal = na.child[it.lane] > 0, b_internal = nb.child[j] > 0;
          if (b_internal) stack.push_back({it.na, it.lane, nb.child[j], it.ref_a, child_ref(it.ref_b, nb, j)});
          if (a_internal && b_internal) {
            const std::int32_t ca = na.child[it.lane];
            for (int i = 0; i < kWideLanes; ++i)
              if (!is_empty_lane(wa.nodes[ca], i))
                stack.push_back({ca, i, nb.child[j], child_ref(it.ref_a, na, it.lane), child_ref(it.ref_b, nb, j)});
          }
        }
      }
    }
  }
  EXPECT_EQ(missed, 0u);
  EXPECT_EQ(missed_swapped, 0u);
  EXPECT_EQ(lanes_differ, 0u) << (avx2 ? "AVX2" : "two four-lane calls");
  EXPECT_EQ(portable_differ, 0u) << "portable lanes";
  EXPECT_GT(kept_double, 1000u);
  std::printf("[ wide     ] %zu real box pairs: double keeps %zu, float keeps %zu, swapped float keeps %zu\n", tested,
              kept_double, kept_float, kept_swapped);
}

// The kernel with A's M a signed permutation (wide_overlap_permuted: the rays of contains())
// decides as the generic kernel, bit for bit, in four SSE lanes, the portable lanes and eight
// AVX2 lanes: axis-aligned boxes of A (segments and flat boxes too) of every orientation sign,
// at scales 1e-3 to 1e4 and offsets up to 1e6, against the nodes of wide trees over a sphere and
// a soup of random triangles (no mesh file: scripts/check-aarch64 runs it on the portable lanes).
TEST(WideNodes, PermutedKernelIsTheKernel) {
  std::mt19937_64 rng(3801);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const bool avx2 = avx2_bounds_available();
  std::size_t calls = 0, kept_lanes = 0, differ = 0;
  for (const double scale : {1e-3, 1.0, 1e4}) {
    for (const double offset : {0.0, 1e6}) {
      Mesh mesh = offset == 0.0 ? query_test::uv_sphere(20, 30) : query_test::random_soup(600, 3802);
      const Vec3 shift = offset * Vec3(unit(rng), unit(rng), unit(rng));
      for (Vec3& v : mesh.vertices) v = scale * v + shift;
      const Tree tree = build(mesh);
      const WideTree wide = build_wide(tree);
      const Obb root = tree.nodes[0].box.obb();
      const WideFrame f = wide_frame(Pose::identity(), 0.0, wide.eta, 0.0);
      for (int trial = 0; trial < 40; ++trial) {
        const int k = trial % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        const float sign = trial % 2 == 0 ? 1.0f : -1.0f;
        WideBox a{};
        a.axes[k] = sign;
        a.axes[3 + k1] = 1.0f;
        a.axes[6 + k2] = sign;
        const double size = root.half_extents.norm();
        for (int i = 0; i < 3; ++i)
          a.half[i] = trial % 4 == 3 && i > 0 ? 0.0f : static_cast<float>(size * (0.01 + std::abs(unit(rng))));
        const Vec3 ref = root.center + 0.8 * size * Vec3(unit(rng), unit(rng), unit(rng));
        const WidePermutation perm{{k, k1, k2}, {sign, 1.0f, sign}};
        // A walk down the wide tree along the kept lanes (the descent's refs), testing every node.
        std::vector<std::pair<std::int32_t, Vec3>> stack{{0, wide.root_ref}};
        while (!stack.empty()) {
          const auto [n, node_ref] = stack.back();
          stack.pop_back();
          const WideNode& node = wide.nodes[static_cast<std::size_t>(n)];
          const WideHoisted h = hoist(f, wide_pair(f, ref, node_ref), a);
          const unsigned kept = wide_overlap(h, node);
          ++calls;
          if (wide_overlap_permuted(h, perm, node) != kept) ++differ;
          if (wide_overlap_permuted<P4>(h, perm, node) != kept) ++differ;
          if (wide_overlap2_permuted(h, node, h, wide.nodes[0], perm, avx2) != (kept | wide_overlap(h, wide.nodes[0]) << 4))
            ++differ;
          for (unsigned m = kept; m != 0; m &= m - 1) {
            const int lane = std::countr_zero(m);
            ++kept_lanes;
            if (node.child[lane] > 0) stack.push_back({node.child[lane], child_ref(node_ref, node, lane)});
          }
        }
      }
    }
  }
  EXPECT_EQ(differ, 0u) << (avx2 ? "AVX2" : "two four-lane calls");
  EXPECT_GT(calls, 1000u);
  EXPECT_GT(kept_lanes, 1000u);
}

// The point bound of the closest-point search (wide_point_bounds: a point hoisted as a box of half
// extents 0 with the identity's axes, hoist_identity) is 0 for a point in a child box (on its faces,
// edges and corners too) and never above the point's exact distance to the box, at scales 1e-3
// to 1e4 and offsets up to 1e6; close to it (within 1e-4 of the scale); the portable lanes give the
// same bounds bit for bit; and hoist_identity is hoist() of wide_pair() bit for bit.
TEST(WideNodes, PointBoundIsALowerBound) {
  std::mt19937_64 rng(3803);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap(0.0, 0.5);
  int inside = 0, outside = 0, close = 0;
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const double offset : {0.0, 1e3, 1e6})
      for (int n = 0; n < 120; ++n) {
        const Vec3 p = offset * Vec3(unit(rng), unit(rng), unit(rng)) + scale * Vec3(unit(rng), unit(rng), unit(rng));
        const Mat3 axes = n % 3 == 0 ? Mat3::Identity() : random_rotation(rng);
        Obb box = box_around(rng, p, scale, axes);
        const Vec3 ref = box.center + scale * Vec3(unit(rng), unit(rng), unit(rng));
        double eta = 0.0;
        WideNode node = empty_node();
        put_lane(node, n % 4, box, ref, eta);
        const WideFrame f = wide_frame(Pose::identity(), 0.0, eta, 0.0);
        WideBox point{};
        point.axes[0] = point.axes[4] = point.axes[8] = 1.0f;
        const WideHoisted hoisted = hoist(f, WidePair{{0.0f, 0.0f, 0.0f}, 0.0f}, point);
        const WidePermutation identity{{0, 1, 2}, {1.0f, 1.0f, 1.0f}};
        const auto bound_at = [&](const Vec3& q) {
          const WideHoisted h = hoist_identity(f, hoisted, point, q, ref);
          const WideHoisted g = hoist(f, wide_pair(f, q, ref), point);
          for (int i = 0; i < 3; ++i) EXPECT_EQ(h.tn[i], g.tn[i]);
          EXPECT_EQ(h.base, g.base);
          float b[kWideLanes], b_portable[kWideLanes];
          wide_point_bounds(h, identity, node, wide_bound_constants(f), b);
          wide_point_bounds<P4>(h, identity, node, wide_bound_constants(f), b_portable);
          for (int l = 0; l < kWideLanes; ++l) EXPECT_EQ(b[l], b_portable[l]);
          return static_cast<double>(b[n % 4]);
        };
        ++inside;
        EXPECT_EQ(bound_at(p), 0.0) << "scale " << scale << " offset " << offset << " n " << n;
        // A point off the box: its exact distance, from its coordinates in the box's frame.
        const Vec3 q = p + scale * (0.05 + gap(rng)) * Vec3(unit(rng), unit(rng), unit(rng)).normalized();
        const Vec3 local = box.axes.transpose() * (q - box.center);
        const double exact = (local - local.cwiseMax(-box.half_extents).cwiseMin(box.half_extents)).norm();
        const double bound = bound_at(q);
        EXPECT_LE(bound, exact + 1e-12 * (scale + offset)) << "scale " << scale << " offset " << offset << " n " << n;
        if (exact > 0.0) {
          ++outside;
          close += bound >= exact - 1e-4 * scale - 1e-6 * offset;
        }
      }
  EXPECT_GE(outside, 500);
  EXPECT_GE(close, outside * 95 / 100) << close << " of " << outside;
  EXPECT_GT(inside, 0);
}

}  // namespace
}  // namespace tightbvh
