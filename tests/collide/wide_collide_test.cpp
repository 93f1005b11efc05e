// collide's descent over wide trees (src/collide/wide_collide.hpp) gives collide()'s answers:
// all_pairs the same set of triangle pairs, first_hit the same yes/no (and a pair that touches),
// on the shipped meshes over random poses (deep overlap, near first contact on either side,
// separated) at the origin and 1e5 away from it, and brute force's answers on small meshes. The
// distance search over wide trees (distance_wide) gives distance()'s distance on the same poses,
// with its options, and brute force's on small meshes.
#include "collide/wide_collide.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "query_fixtures.hpp"
#include "tightbvh/aabb.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tri_distance.hpp"
#include "tightbvh/tri_tri.hpp"

namespace tightbvh {
namespace {

using namespace query_detail;

using query_test::random_rotation;

Mesh shipped_mesh(const char* name) { return load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/" + name); }

struct Model {
  Mesh mesh;
  Tree tree;
  WideTree wide;
  Vec3 center;
  double radius;
};

Model model(Mesh mesh) {
  Model m{std::move(mesh), {}, {}, Vec3::Zero(), 0.0};
  m.tree = build(m.mesh);
  m.wide = build_wide(m.tree);
  Aabb box;
  for (const Vec3& v : m.mesh.vertices) box.extend(v);
  m.center = box.center();
  m.radius = 0.5 * box.diagonal();
  return m;
}

// Checks collide_wide against collide() for B at `rel`; returns whether they touch.
bool check_pose(const Model& a, const Model& b, const Pose& rel, const std::string& where) {
  const QueryResult all =
      collide(a.tree, a.mesh, Pose::identity(), b.tree, b.mesh, rel, {.mode = QueryMode::all_pairs});
  const QueryResult wide = collide_wide(a.tree, a.wide, a.mesh, b.tree, b.wide, b.mesh, rel, QueryMode::all_pairs);
  EXPECT_EQ(wide.pairs, all.pairs) << where;
  EXPECT_EQ(wide.hit, all.hit) << where;
  const QueryResult first = collide_wide(a.tree, a.wide, a.mesh, b.tree, b.wide, b.mesh, rel, QueryMode::first_hit);
  EXPECT_EQ(first.hit, all.hit) << where;
  if (first.hit) {
    EXPECT_EQ(first.pairs.size(), 1u) << where;
    if (!first.pairs.empty()) {  // the pair found touches: it is one of all_pairs'
      EXPECT_TRUE(std::binary_search(all.pairs.begin(), all.pairs.end(), first.pairs[0])) << where;
    }
  }
  EXPECT_GE(wide.stats.box_tests, 1u) << where;
  EXPECT_GE(wide.stats.triangle_tests, wide.pairs.size()) << where;
  // The distance search over the wide nodes: distance()'s distance, bit for bit (both the least
  // triangle distance, each pair measured alike), 0 exactly where collide() hits, and a pair at it.
  QueryWorkspace ws;
  const DistanceResult d = distance(a.tree, a.mesh, Pose::identity(), b.tree, b.mesh, rel);
  const DistanceResult dw =
      distance_wide(a.tree, a.wide, a.mesh, Pose::identity(), b.tree, b.wide, b.mesh, rel, {}, ws);
  EXPECT_EQ(dw.distance, d.distance) << where;
  EXPECT_EQ(dw.distance == 0.0, all.hit) << where;
  if (dw.distance > 0.0) {
    const auto [p0, p1, p2] = a.mesh.corners(dw.pair.a);
    const Triangle& t = b.mesh.triangles[dw.pair.b];
    const TriangleDistance td = tri_tri_distance(p0, p1, p2, rel.apply(b.mesh.vertices[t[0]]),
                                                 rel.apply(b.mesh.vertices[t[1]]), rel.apply(b.mesh.vertices[t[2]]));
    EXPECT_NEAR(td.distance, dw.distance, 1e-9 * (1.0 + dw.distance)) << where;
    EXPECT_NEAR((dw.point_a - dw.point_b).norm(), dw.distance, 1e-9 * (1.0 + dw.distance)) << where;
  }
  return all.hit;
}

// B approaching A along a random direction with a random rotation: B's center at A's plus d dir,
// and first contact bracketed by bisection on collide()'s first_hit answer (lo touching, hi apart,
// 24 halvings of the size).
struct Approach {
  Mat3 rot;
  Vec3 dir, center_a, center_b;
  double lo = 0.0, hi = 0.0;
  [[nodiscard]] Pose at(double d) const { return Pose{rot, Vec3(center_a + d * dir - rot * center_b)}; }
};

Approach approach(const Model& a, const Model& b, std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Approach x{random_rotation(rng), Vec3::Zero(), a.center, b.center};
  x.dir = Vec3(n(rng), n(rng), n(rng)).normalized();
  const auto hit = [&](double d) { return collide(a.tree, a.mesh, Pose::identity(), b.tree, b.mesh, x.at(d), {}).hit; };
  x.hi = a.radius + b.radius;
  if (!hit(x.lo)) x.lo = x.hi;
  for (int k = 0; k < 24 && x.lo < x.hi; ++k) {
    const double mid = 0.5 * (x.lo + x.hi);
    (hit(mid) ? x.lo : x.hi) = mid;
  }
  return x;
}

// Random poses of B about A: deep overlap (centers 0.15 (ra + rb) apart), near first contact
// (0.2% of the size deeper and shallower), and separated (2% beyond first contact).
void check_pair(const Model& a, const Model& b, int poses, std::mt19937_64& rng, const std::string& name,
                int& touching, int& apart) {
  const double size = a.radius + b.radius;
  for (int i = 0; i < poses; ++i) {
    const Approach x = approach(a, b, rng);
    const std::string where = name + " pose " + std::to_string(i);
    const double ds[] = {0.15 * size, x.lo - 0.002 * size, x.hi + 0.002 * size, x.hi + 0.02 * size, x.lo};
    for (const double d : ds) (check_pose(a, b, x.at(d), where + " d " + std::to_string(d)) ? touching : apart)++;
  }
}

TEST(WideCollide, SamePairsAsCollideOnShippedMeshes) {
  std::mt19937_64 rng(38);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const double offset : {0.0, 1e5}) {
    // Far from the origin: both meshes moved in their own frames.
    const auto moved = [&](const char* name) {
      Mesh m = shipped_mesh(name);
      const Vec3 shift = offset * Vec3(unit(rng), unit(rng), unit(rng));
      for (Vec3& v : m.vertices) v += shift;
      return model(std::move(m));
    };
    const Model knot = moved("knot1.off"), elephant = moved("elephant.off"), fandisk = moved("fandisk.off");
    int touching = 0, apart = 0;
    const std::string at = " at " + std::to_string(offset);
    check_pair(knot, elephant, 12, rng, "knot1/elephant" + at, touching, apart);
    check_pair(elephant, fandisk, 6, rng, "elephant/fandisk" + at, touching, apart);
    check_pair(fandisk, knot, 6, rng, "fandisk/knot1" + at, touching, apart);
    // The poses cover both answers.
    EXPECT_GE(touching, 40) << at;
    EXPECT_GE(apart, 40) << at;
  }
}

// With a margin: the pairs within it, as collide() reports them, near first contact and apart by
// about the margin, at the origin and far from it.
TEST(WideCollide, SamePairsAsCollideWithAMargin) {
  std::mt19937_64 rng(39);
  for (const double offset : {0.0, 1e5}) {
    Mesh mk = shipped_mesh("knot1.off"), me = shipped_mesh("elephant.off");
    for (Vec3& v : mk.vertices) v += Vec3(offset, -offset, 0.5 * offset);
    const Model knot = model(std::move(mk)), elephant = model(std::move(me));
    const double size = knot.radius + elephant.radius, margin = 0.005 * size;
    int within = 0, apart = 0;
    for (int i = 0; i < 8; ++i) {
      const Approach x = approach(knot, elephant, rng);
      for (const double d : {x.lo, x.hi + 0.5 * margin, x.hi + 2.0 * margin, x.hi + 0.05 * size}) {
        const Pose rel = x.at(d);
        const QueryOptions o{.mode = QueryMode::all_pairs, .margin = margin};
        const QueryResult expected = collide(knot.tree, knot.mesh, Pose::identity(), elephant.tree, elephant.mesh, rel, o);
        const QueryResult got = collide_wide(knot.tree, knot.wide, knot.mesh, elephant.tree, elephant.wide,
                                             elephant.mesh, rel, QueryMode::all_pairs, margin);
        EXPECT_EQ(got.pairs, expected.pairs) << "offset " << offset << " pose " << i << " d " << d;
        (expected.hit ? within : apart)++;
      }
    }
    EXPECT_GE(within, 12) << offset;
    EXPECT_GE(apart, 3) << offset;
  }
}

// A random soup of n triangles of size ~s in the unit cube, with some corners shared.
Mesh soup(std::mt19937_64& rng, int n, double s) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), small(-s, s);
  Mesh m;
  for (int i = 0; i < n; ++i) {
    const Vec3 c(unit(rng), unit(rng), unit(rng));
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    for (int k = 0; k < 3; ++k) m.vertices.push_back(c + Vec3(small(rng), small(rng), small(rng)));
    m.triangles.push_back({base, base + 1, base + 2});
    if (i > 0 && i % 3 == 0) m.triangles.push_back({base, base - 1, base + 1});  // shares corners
  }
  return m;
}

TEST(WideCollide, SamePairsAsBruteForceOnSmallMeshes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int hits = 0;
  for (int round = 0; round < 12; ++round) {
    const Model a = model(soup(rng, 120, 0.12)), b = model(soup(rng, 90, 0.15));
    for (int p = 0; p < 4; ++p) {
      // p == 0: B at identity (shared corner positions touch exactly).
      const Pose rel = p == 0 ? Pose::identity()
                              : Pose{random_rotation(rng), Vec3(0.5, 0.5, 0.5) + 0.4 * Vec3(unit(rng), unit(rng), unit(rng))};
      const QueryResult brute = collide_brute_force(a.mesh, Pose::identity(), b.mesh, rel, {.mode = QueryMode::all_pairs});
      const QueryResult wide = collide_wide(a.tree, a.wide, a.mesh, b.tree, b.wide, b.mesh, rel, QueryMode::all_pairs);
      EXPECT_EQ(wide.pairs, brute.pairs) << "round " << round << " pose " << p;
      const QueryResult first = collide_wide(a.tree, a.wide, a.mesh, b.tree, b.wide, b.mesh, rel, QueryMode::first_hit);
      EXPECT_EQ(first.hit, brute.hit) << "round " << round << " pose " << p;
      hits += brute.hit;
      // The distance search over the wide nodes: brute force's distance, far poses too.
      for (const double away : {0.0, 0.3, 2.0}) {
        const Pose moved{rel.rotation, Vec3(rel.translation + Vec3(away, -0.5 * away, 0.25 * away))};
        const double expected = distance_brute_force(a.mesh, Pose::identity(), b.mesh, moved).distance;
        QueryWorkspace ws;
        const double got =
            distance_wide(a.tree, a.wide, a.mesh, Pose::identity(), b.tree, b.wide, b.mesh, moved, {}, ws).distance;
        EXPECT_NEAR(got, expected, 1e-12 * (1.0 + expected)) << "round " << round << " pose " << p << " away " << away;
        EXPECT_EQ(got == 0.0, expected == 0.0) << "round " << round << " pose " << p << " away " << away;
      }
    }
  }
  EXPECT_GE(hits, 24);
}

// Leaves of several triangles: their references pack the count (leaf_bits), and leaves larger than
// a reference holds are split over lanes of a node below (build_wide's max_leaf_bits forces that
// here). Every triangle is in exactly one leaf reference, and the pairs are brute force's.
TEST(WideCollide, LargeLeavesPackedAndSplit) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int hits = 0, split_nodes = 0;
  for (int round = 0; round < 4; ++round) {
    const Mesh ma = soup(rng, 150, 0.12), mb = soup(rng, 110, 0.15);
    const Tree ta = build(ma, {.leaf_size = 7}), tb = build(mb, {.leaf_size = 5});
    for (const int max_bits : {31, 1, 0}) {
      const WideTree wa = build_wide(ta, nullptr, max_bits), wb = build_wide(tb, nullptr, max_bits);
      EXPECT_LE(wa.leaf_bits, max_bits);
      for (const auto* w : {&wa, &wb}) {  // each triangle in one leaf reference
        std::vector<int> seen(w == &wa ? ma.triangles.size() : mb.triangles.size(), 0);
        for (const WideNode& n : w->nodes)
          for (int lane = 0; lane < kWideLanes; ++lane) {
            if (n.child[lane] >= 0) continue;
            const WideTree::LeafRange leaf = w->leaf(n.child[lane]);
            EXPECT_LE(leaf.count, 1u << w->leaf_bits);
            const Tree& t = w == &wa ? ta : tb;
            for (std::uint32_t k = 0; k < leaf.count; ++k) ++seen[t.triangle_order[leaf.first + k]];
          }
        EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; })) << "bits " << max_bits;
      }
      if (max_bits == 0) split_nodes += static_cast<int>(wa.nodes.size()) - static_cast<int>(build_wide(ta).nodes.size());
      for (int p = 0; p < 3; ++p) {
        const Pose rel{random_rotation(rng), Vec3(0.5, 0.5, 0.5) + 0.4 * Vec3(unit(rng), unit(rng), unit(rng))};
        const QueryResult brute = collide_brute_force(ma, Pose::identity(), mb, rel, {.mode = QueryMode::all_pairs});
        const QueryResult wide = collide_wide(ta, wa, ma, tb, wb, mb, rel, QueryMode::all_pairs);
        EXPECT_EQ(wide.pairs, brute.pairs) << "round " << round << " bits " << max_bits << " pose " << p;
        EXPECT_EQ(collide_wide(ta, wa, ma, tb, wb, mb, rel, QueryMode::first_hit).hit, brute.hit);
        hits += brute.hit;
      }
    }
  }
  EXPECT_GT(split_nodes, 0);  // max_leaf_bits 0 did split leaves
  EXPECT_GE(hits, 12);
}

// The descent's float steps stay within their error bounds (wide_collide.cpp's derivation): along
// random walks down knot1 and fandisk (at the origin and 1e5 away, random poses), moving B's node
// (move_b), opening A's box (move_a, fresh), B's ref in A's node frame (t) and in A's box frame
// (tn), and A's node ref in B's node frame for the swapped tests (swap_point), are within their
// error bounds of their values computed in long double from the refs, the steps' bounds within
// those the descent uses for the whole query (descent_bounds), each
// step's own error within its bound's growth; and the bounds stay small against the boxes.
TEST(WideCollide, MovedReferencePointsWithinTheirBounds) {
  std::mt19937_64 rng(380);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int steps = 0;
  for (const double offset : {0.0, 1e5}) {
    Mesh ma = shipped_mesh("knot1.off"), mb = shipped_mesh("fandisk.off");
    const Vec3 sa = offset * Vec3(unit(rng), unit(rng), unit(rng)), sb = offset * Vec3(unit(rng), unit(rng), unit(rng));
    for (Vec3& v : ma.vertices) v += sa;
    for (Vec3& v : mb.vertices) v += sb;
    const Model a = model(std::move(ma)), b = model(std::move(mb));
    const double size = a.radius + b.radius;
    for (int pose = 0; pose < 40; ++pose) {
      const Mat3 rot = random_rotation(rng);
      const Pose rel{rot, a.center - rot * b.center + 0.5 * size * Vec3(unit(rng), unit(rng), unit(rng))};
      const WideFrame f = wide_frame(rel, a.wide.eta, b.wide.eta, 0.0);
      const WideFrame fs = wide_frame_swapped(rel, a.wide.eta, b.wide.eta, 0.0);
      const WidePair root = wide_pair(f, a.wide.root_ref, b.wide.root_ref);
      const DescentBounds query = descent_bounds(a.wide, b.wide, root);
      EXPECT_LT(query.t_err, 1e-5 * size);
      EXPECT_LT(query.err, 1e-5 * size);
      const auto check = [&](const DescentBox& x, const Vec3& ref_a, const Vec3& ref_b) {
        long double t[3], d[3];
        for (int k = 0; k < 3; ++k) {
          t[k] = -static_cast<long double>(ref_a[k]) + static_cast<long double>(rel.translation[k]);
          for (int l = 0; l < 3; ++l)
            t[k] += static_cast<long double>(rel.rotation(k, l)) * static_cast<long double>(ref_b[l]);
          EXPECT_LE(std::abs(static_cast<double>(static_cast<long double>(x.t[k]) - t[k])), x.t_err);
          d[k] = t[k] - static_cast<long double>(x.node().center[k][x.lane]);
        }
        for (int i = 0; i < 3; ++i) {
          long double tn = 0.0L;
          for (int k = 0; k < 3; ++k) tn += static_cast<long double>(x.node().axes[3 * i + k][x.lane]) * d[k];
          EXPECT_LE(std::abs(static_cast<double>(static_cast<long double>(x.tn[i]) - tn)), x.err);
        }
        EXPECT_LT(x.err, 1e-5 * size);
        // The bounds the descent uses for the whole query cover what the steps accumulate.
        EXPECT_LE(x.t_err, query.t_err);
        EXPECT_LE(x.err, query.err);
        // A's node ref in B's node frame under the swapped frame, from t (swap_point), within its
        // bound of R0^T ref_a + t0' - ref_b (t0' as the swapped frame rounded it).
        float sw[3];
        double sw_err = 0.0;
        swap_point(f.r0, x.t, x.t_err, fs.swap_rel * b.wide.ref_bound + fs.swap_abs, sw, sw_err);
        for (int k = 0; k < 3; ++k) {
          long double exact = static_cast<long double>(fs.t0_d[k]) - static_cast<long double>(ref_b[k]);
          for (int l = 0; l < 3; ++l)
            exact += static_cast<long double>(fs.r0_d(k, l)) * static_cast<long double>(ref_a[l]);
          EXPECT_LE(std::abs(static_cast<double>(static_cast<long double>(sw[k]) - exact)), sw_err);
        }
        EXPECT_LT(sw_err, 1e-5 * size);
        ++steps;
      };
      // hoist_node's lanes are hoist's boxes, operation for operation.
      const auto same_as_hoist = [&](const HoistedNode& hn, const float (&t)[3]) {
        for (int lane = 0; lane < kWideLanes; ++lane) {
          if (is_empty_lane(*hn.node, lane)) continue;
          const WideHoisted h = hoist(f, WidePair{{t[0], t[1], t[2]}, 0.0f}, lane_box(*hn.node, lane));
          for (int r = 0; r < 9; ++r) EXPECT_EQ(h.m[r], hn.k.m[r][lane]);
          for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(h.tn[i], hn.tn[i][lane]);
            EXPECT_EQ(h.ea[i], hn.k.ea[i][lane]);
          }
        }
      };
      const auto random_lane = [&](const WideNode& n) {
        int lanes[kWideLanes], count = 0;
        for (int l = 0; l < kWideLanes; ++l)
          if (!is_empty_lane(n, l)) lanes[count++] = l;
        return lanes[std::uniform_int_distribution<int>(0, count - 1)(rng)];
      };
      std::deque<HoistedNode> hoisted;  // the boxes' nodes, kept while the walk uses them
      hoisted.push_back(hoist_node(f, a.wide.nodes[0], root.t, static_cast<double>(root.t_err)));
      same_as_hoist(hoisted.back(), root.t);
      DescentBox x = fresh(hoisted.back(), random_lane(a.wide.nodes[0]), root.t, static_cast<double>(root.t_err));
      std::int32_t nb = 0;
      Vec3 ref_a = a.wide.root_ref, ref_b = b.wide.root_ref;
      for (int step = 0; step < 40; ++step) {
        check(x, ref_a, ref_b);
        const WideNode& n = b.wide.nodes[static_cast<std::size_t>(nb)];
        for (int l = 0; l < kWideLanes; ++l) {  // the swapped tests' bound on B's box points
          if (is_empty_lane(n, l)) continue;
          double reach = 0.0;
          for (int k = 0; k < 3; ++k) reach = std::max(reach, std::abs(ref_b[k] + static_cast<double>(n.center[k][l])));
          EXPECT_LE(reach + 1.01 * (n.half[0][l] + n.half[1][l] + n.half[2][l]), b.wide.reach_bound);
        }
        int b_lanes[kWideLanes], nbl = 0;
        for (int l = 0; l < kWideLanes; ++l)
          if (n.child[l] > 0) b_lanes[nbl++] = l;
        const bool a_open = x.node().child[x.lane] > 0;
        if (nbl == 0 && !a_open) break;
        if (nbl > 0 && (!a_open || unit(rng) < 0.6)) {  // B's side
          const int lane = b_lanes[std::uniform_int_distribution<int>(0, nbl - 1)(rng)];
          const Vec3 ref_c = child_ref(ref_b, n, lane);
          const DescentBox before = x;
          EXPECT_LE(ref_c.lpNorm<1>(), b.wide.ref_bound);
          move_b(x, n, lane, ref_round(b.wide), f.r0);
          // The step alone is within the bound's growth: tn and t moved by A^T R0 (ref_c - ref_b)
          // and R0 (ref_c - ref_b), computed in long double.
          long double moved[3];
          for (int k = 0; k < 3; ++k) {
            moved[k] = 0.0L;
            for (int l = 0; l < 3; ++l)
              moved[k] += static_cast<long double>(rel.rotation(k, l)) *
                          (static_cast<long double>(ref_c[l]) - static_cast<long double>(ref_b[l]));
            EXPECT_LE(std::abs(static_cast<double>(static_cast<long double>(x.t[k]) -
                                                   static_cast<long double>(before.t[k]) - moved[k])),
                      x.t_err - before.t_err);
          }
          for (int i = 0; i < 3; ++i) {
            long double step = 0.0L;
            for (int k = 0; k < 3; ++k) step += static_cast<long double>(x.node().axes[3 * i + k][x.lane]) * moved[k];
            EXPECT_LE(std::abs(static_cast<double>(static_cast<long double>(x.tn[i]) -
                                                   static_cast<long double>(before.tn[i]) - step)),
                      x.err - before.err);
          }
          nb = n.child[lane];
          ref_b = ref_c;
        } else {  // A's side
          const Vec3 ref_c = child_ref(ref_a, x.node(), x.lane);
          float t[3];
          double t_err = 0.0;
          EXPECT_LE(ref_c.lpNorm<1>(), a.wide.ref_bound);
          move_a(x, ref_round(a.wide), t, t_err);
          for (int k = 0; k < 3; ++k)  // the step alone: t moved by -(ref_c - ref_a)
            EXPECT_LE(std::abs(static_cast<double>(static_cast<long double>(t[k]) - static_cast<long double>(x.t[k]) +
                                                   (static_cast<long double>(ref_c[k]) -
                                                    static_cast<long double>(ref_a[k])))),
                      t_err - x.t_err);
          const WideNode& na = a.wide.nodes[static_cast<std::size_t>(x.node().child[x.lane])];
          hoisted.push_back(hoist_node(f, na, t, t_err));
          same_as_hoist(hoisted.back(), t);
          x = fresh(hoisted.back(), random_lane(na), t, t_err);
          ref_a = ref_c;
        }
      }
    }
  }
  EXPECT_GE(steps, 1000);
}

// distance_wide with distance()'s options: an upper bound (beyond it: the bound, flagged), an
// allowed relative and absolute error (within them of the exact distance), a solid inside the
// other (0), and the same errors for bad options as distance().
TEST(WideCollide, DistanceSearchOptions) {
  std::mt19937_64 rng(40);
  const Model knot = model(shipped_mesh("knot1.off")), elephant = model(shipped_mesh("elephant.off"));
  QueryWorkspace ws;
  const auto wide = [&](const Pose& rel, const DistanceOptions& o) {
    return distance_wide(knot.tree, knot.wide, knot.mesh, Pose::identity(), elephant.tree, elephant.wide,
                         elephant.mesh, rel, o, ws);
  };
  int apart = 0;
  for (int i = 0; i < 6; ++i) {
    const Approach x = approach(knot, elephant, rng);
    const Pose rel = x.at(x.hi + 0.03 * (knot.radius + elephant.radius));
    const double exact = distance(knot.tree, knot.mesh, Pose::identity(), elephant.tree, elephant.mesh, rel).distance;
    if (!(exact > 0.0)) continue;
    ++apart;
    const DistanceResult beyond = wide(rel, {.upper_bound = 0.5 * exact});
    EXPECT_TRUE(beyond.beyond_upper_bound) << i;
    EXPECT_EQ(beyond.distance, 0.5 * exact) << i;
    const DistanceResult within = wide(rel, {.upper_bound = 2.0 * exact});
    EXPECT_FALSE(within.beyond_upper_bound) << i;
    EXPECT_EQ(within.distance, exact) << i;
    const DistanceResult rough = wide(rel, {.absolute_error = 1e-3 * exact, .relative_error = 0.2});
    EXPECT_GE(rough.distance, exact) << i;
    EXPECT_LE(rough.distance, 1.2 * exact + 1e-3 * exact + 1e-12) << i;
  }
  EXPECT_GE(apart, 4);
  // A sphere well inside a larger one: the surfaces apart, the solids not.
  Mesh small = query_test::uv_sphere(12, 16, 0.2), large = query_test::uv_sphere(12, 16, 1.0);
  const Model inner = model(std::move(small)), outer = model(std::move(large));
  const Closedness ci = check_closed(inner.mesh), co = check_closed(outer.mesh);
  const DistanceResult solid = distance_wide(outer.tree, outer.wide, outer.mesh, Pose::identity(), inner.tree,
                                             inner.wide, inner.mesh, Pose::identity(),
                                             {.solid = true, .closed_a = &co, .closed_b = &ci}, ws);
  EXPECT_EQ(solid.distance, 0.0);
  EXPECT_EQ(solid.inside, Inside::b_in_a);
  const DistanceResult surfaces = distance_wide(outer.tree, outer.wide, outer.mesh, Pose::identity(), inner.tree,
                                                inner.wide, inner.mesh, Pose::identity(), {}, ws);
  EXPECT_NEAR(surfaces.distance, 0.8, 0.05);
  EXPECT_THROW((void)wide(Pose::identity(), {.relative_error = -1.0}), InputError);
}

TEST(WideCollide, EmptyTreesAndBadPose) {
  const Model a = model(shipped_mesh("knot1.off"));
  const QueryResult none = collide_wide(a.tree, WideTree{}, a.mesh, a.tree, a.wide, a.mesh, Pose::identity(),
                                        QueryMode::all_pairs);
  EXPECT_FALSE(none.hit);
  Pose bad = Pose::identity();
  bad.translation.x() = std::nan("");
  EXPECT_THROW((void)collide_wide(a.tree, a.wide, a.mesh, a.tree, a.wide, a.mesh, Pose::identity(),
                                  QueryMode::all_pairs, -1.0),
               InputError);
  EXPECT_THROW((void)collide_wide(a.tree, a.wide, a.mesh, a.tree, a.wide, a.mesh, bad, QueryMode::first_hit),
               InputError);
}

}  // namespace
}  // namespace tightbvh
