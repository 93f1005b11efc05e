// Micro-benchmarks of the overlap kernels (15-axis SAT, exact triangle-triangle test) and a
// traversal benchmark: box tests and triangle tests per query for trees of each fitter on the
// shipped mesh pair (knot1 vs elephant), in three scenarios.
//
//   build/bin/tightbvh-collide-bench --benchmark_filter=Traversal
//
// Counters: box_tests and tri_tests are per query (averaged over the scenario's poses).
//
// The cost model (docs/design-notes/collide.md, "Where a query's time goes (the cost model)"):
// BM_ReplayBoxTests and BM_ReplayTriangleTests replay, without the descent around them, exactly the
// box tests and the triangle tests that collide() made on the auto trees of each scenario (recorded
// with collide_trace), so that (box tests x their cost + triangle tests x theirs) can be held
// against BM_Traversal's measured query time: bench/collide/cost_model.py prints the table.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "collide/box_test.hpp"
#include "collide/query_common.hpp"
#include "collide/query_workspace.hpp"
#include "collide/tri_batch.hpp"
#include "collide/wide_collide.hpp"
#include "collide/wide_nodes.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/collide_trace.hpp"
#include "tightbvh/obb_overlap.hpp"
#include "tightbvh/tri_tri.hpp"

namespace {

using namespace tightbvh;

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
}

// ---------------------------------------------------------------- SAT
struct BoxPair {
  Mat3 r;
  Vec3 t, ea, eb;
};

// Random box pairs; `spread` sets the distance of the centers (about half overlap at 2).
std::vector<BoxPair> box_pairs(double spread) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.1, 1.0), c(-spread, spread);
  std::vector<BoxPair> pairs(1024);
  for (auto& p : pairs) p = {random_rotation(rng), Vec3(c(rng), c(rng), c(rng)), Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
  return pairs;
}

void BM_Sat(benchmark::State& state) {
  const auto pairs = box_pairs(static_cast<double>(state.range(0)));
  std::size_t i = 0, overlaps = 0;
  for (auto _ : state) {
    const BoxPair& p = pairs[i++ & 1023];
    const bool o = obb_overlap(p.r, p.t, p.ea, p.eb);
    overlaps += o;
    benchmark::DoNotOptimize(o);
  }
  state.counters["overlap_fraction"] = static_cast<double>(overlaps) / static_cast<double>(state.iterations());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Sat)->Arg(1)->Arg(2)->Arg(4)->ArgName("spread");

// Two boxes in different frames: the per-node-pair work of the traversal (map B's box into A's
// box frame, then SAT).
void BM_SatWithTransform(benchmark::State& state) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.1, 1.0), c(-2, 2);
  std::vector<Obb> boxes(1024);
  for (auto& b : boxes) b = {Vec3(c(rng), c(rng), c(rng)), random_rotation(rng), Vec3(u(rng), u(rng), u(rng))};
  const Pose rel{random_rotation(rng), Vec3(0.1, 0.2, 0.3)};
  std::size_t i = 0;
  for (auto _ : state) {
    const Obb& a = boxes[i & 1023];
    const Obb& b = boxes[(i * 7 + 3) & 1023];
    ++i;
    const Mat3 ra = a.axes.transpose() * rel.rotation;
    const Mat3 r = ra * b.axes;
    const Vec3 t = ra * b.center + a.axes.transpose() * (rel.translation - a.center);
    benchmark::DoNotOptimize(obb_overlap(r, t, a.half_extents, b.half_extents, 1e-9));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SatWithTransform);

// ---------------------------------------------------------------- triangle-triangle
using Tri = std::array<Vec3, 3>;

// kind 0: random pairs near each other (mixed answers); 1: crossing pairs; 2: pairs sharing an
// edge (mesh neighbours); 3: coplanar in a plane z = const; 4: (nearly) coplanar in a tilted plane
// (corners rounded onto it: the exact fallback decides).
std::vector<std::pair<Tri, Tri>> triangle_pairs(int kind) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto v = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  std::vector<std::pair<Tri, Tri>> pairs;
  while (pairs.size() < 1024) {
    Tri a{v(), v(), v()}, b{v(), v(), v()};
    if (kind == 0) {
      const Vec3 d = 1.2 * v();
      for (auto& p : b) p += d;
    } else if (kind == 1) {
      if (!tri_tri_overlap(a, b)) continue;
    } else if (kind == 2) {
      b[0] = a[0], b[1] = a[1];
    } else if (kind == 3) {
      for (auto& p : a) p.z() = 0.25;
      for (auto& p : b) p.z() = 0.25;
    } else {
      const Vec3 e1 = Vec3(1, 2, 3).normalized(), e2 = Vec3(3, -1, 0.5).normalized();
      for (auto& p : a) p = p.x() * e1 + p.y() * e2;
      for (auto& p : b) p = p.x() * e1 + p.y() * e2;
    }
    pairs.push_back({a, b});
  }
  return pairs;
}

void BM_TriTri(benchmark::State& state) {
  const auto pairs = triangle_pairs(static_cast<int>(state.range(0)));
  std::size_t i = 0, hits = 0;
  for (auto _ : state) {
    const auto& [a, b] = pairs[i++ & 1023];
    const bool o = tri_tri_overlap(a, b);
    hits += o;
    benchmark::DoNotOptimize(o);
  }
  state.counters["hit_fraction"] = static_cast<double>(hits) / static_cast<double>(state.iterations());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TriTri)->DenseRange(0, 4)->ArgName("kind");

// ---------------------------------------------------------------- traversal
struct Scene {
  Mesh a, b;
  // scenario -> poses of B (A at identity)
  std::vector<Pose> poses[3];
};

const char* kScenarioNames[3] = {"deep", "near", "separated"};

// deep: B's center at 0.15 (rA + rB) from A's; near: just inside first contact along a random
// direction (bisection on the brute-force-validated first_hit answer, then 0.5% of the meshes'
// size deeper); separated: 0.5% outside first contact.
const Scene& scene() {
  static const std::unique_ptr<Scene> s = [] {
    auto sc = std::make_unique<Scene>();
    sc->a = load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/knot1.off");
    sc->b = load_mesh(std::string(TIGHTBVH_SOURCE_DIR) + "/meshes/elephant.off");
    const Tree ta = build(sc->a, {.fitter = FitMethod::aabb});
    const Tree tb = build(sc->b, {.fitter = FitMethod::aabb});
    Aabb ba, bb;
    for (const Vec3& v : sc->a.vertices) ba.extend(v);
    for (const Vec3& v : sc->b.vertices) bb.extend(v);
    const double ra = 0.5 * ba.diagonal(), rb = 0.5 * bb.diagonal();
    std::mt19937_64 rng(4);
    std::normal_distribution<double> n;
    for (int i = 0; i < 32; ++i) {
      const Mat3 rot = random_rotation(rng);
      const Vec3 dir = Vec3(n(rng), n(rng), n(rng)).normalized();
      const auto pose_at = [&](double d) {
        return Pose{rot, Vec3(ba.center() + d * dir - rot * bb.center())};
      };
      const auto hit = [&](double d) {
        return collide(ta, sc->a, Pose::identity(), tb, sc->b, pose_at(d), {}).hit;
      };
      sc->poses[0].push_back(pose_at(0.15 * (ra + rb)));
      double lo = 0.0, hi = ra + rb;  // hit(lo), !hit(hi)
      if (!hit(lo)) lo = hi;          // rare: no contact at the centers; treat as contact at 0
      for (int k = 0; k < 30 && lo < hi; ++k) {
        const double mid = 0.5 * (lo + hi);
        (hit(mid) ? lo : hi) = mid;
      }
      sc->poses[1].push_back(pose_at(lo - 0.005 * (ra + rb)));
      sc->poses[2].push_back(pose_at(hi + 0.005 * (ra + rb)));
    }
    return sc;
  }();
  return *s;
}

// approx-snap is left out: ~45 s per 1000 triangles. exact takes ~30 s for both meshes (once).
const Fitter kFitters[] = {FitMethod::aabb, FitMethod::pca,   FitMethod::pca_vertex, FitMethod::diameter,
                           FitMethod::approx, FitMethod::exact, AutoFit{}};

const Tree* tree_for(const Mesh& mesh, int fitter_index,
                     std::map<std::pair<const Mesh*, int>, std::unique_ptr<Tree>>& cache) {
  const Fitter& fitter = kFitters[fitter_index];
  auto& slot = cache[{&mesh, fitter_index}];
  if (!slot) {
    try {
      slot = std::make_unique<Tree>(build(mesh, {.fitter = fitter}));
    } catch (const std::logic_error&) {
      return nullptr;
    }
  }
  return slot.get();
}

// Args: fitter index, scenario, mode (0 first_hit, 1 all_pairs), descend rule (0 volume, 1 extent).
void BM_Traversal(benchmark::State& state) {
  static std::map<std::pair<const Mesh*, int>, std::unique_ptr<Tree>> cache;
  const Scene& sc = scene();
  const int fitter = static_cast<int>(state.range(0));
  const Tree* ta = tree_for(sc.a, fitter, cache);
  const Tree* tb = tree_for(sc.b, fitter, cache);
  if (!ta || !tb) {
    state.SkipWithError("fitter not implemented yet");
    return;
  }
  const auto& poses = sc.poses[state.range(1)];
  const QueryOptions options{.mode = state.range(2) ? QueryMode::all_pairs : QueryMode::first_hit,
                             .descend = state.range(3) ? DescendRule::larger_extent : DescendRule::larger_volume};
  QueryStats total;
  std::size_t queries = 0, hits = 0, pairs = 0;
  QueryWorkspace workspace;  // reused, as a caller running many queries would
  for (auto _ : state) {
    for (const Pose& pose : poses) {
      const QueryResult r = collide(*ta, sc.a, Pose::identity(), *tb, sc.b, pose, options, workspace);
      total.box_tests += r.stats.box_tests;
      total.triangle_tests += r.stats.triangle_tests;
      hits += r.hit;
      pairs += r.pairs.size();
      ++queries;
    }
  }
  const double q = static_cast<double>(queries);
  state.counters["box_tests"] = static_cast<double>(total.box_tests) / q;
  state.counters["tri_tests"] = static_cast<double>(total.triangle_tests) / q;
  state.counters["hit_rate"] = static_cast<double>(hits) / q;
  state.counters["pairs"] = static_cast<double>(pairs) / q;
  state.counters["queries_per_s"] = benchmark::Counter(q, benchmark::Counter::kIsRate);
  state.SetLabel(to_string(kFitters[fitter]) + "/" + kScenarioNames[state.range(1)] + "/" +
                 (state.range(2) ? "all_pairs" : "first_hit") + (state.range(3) ? "/extent" : ""));
}
BENCHMARK(BM_Traversal)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6}, {0, 1, 2}, {0, 1}, {0}})
    ->ArgNames({"fitter", "scenario", "all_pairs", "descend"})
    ->Unit(benchmark::kMicrosecond);
// The descent rule, measured on pca trees.
BENCHMARK(BM_Traversal)
    ->ArgsProduct({{1}, {0, 1, 2}, {0, 1}, {1}})
    ->ArgNames({"fitter", "scenario", "all_pairs", "descend"})
    ->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------- cost model

constexpr int kAutoFitter = 6;

// What collide() did on the auto trees for each pose of a scenario and mode: the node pairs it
// box-tested, in order, and the leaf pairs whose triangles it tested.
struct Recorded {
  const Tree* ta = nullptr;
  const Tree* tb = nullptr;
  std::vector<std::vector<query_detail::NodePair>> tested, leaves;  // per pose
  std::vector<std::vector<query_detail::NodePair>> descended;       // per pose: the split pairs
};

const Recorded& recorded(int scenario, bool all_pairs) {
  static std::map<std::pair<int, bool>, std::unique_ptr<Recorded>> cache;
  static std::map<std::pair<const Mesh*, int>, std::unique_ptr<Tree>> trees;
  auto& slot = cache[{scenario, all_pairs}];
  if (!slot) {
    const Scene& sc = scene();
    slot = std::make_unique<Recorded>();
    slot->ta = tree_for(sc.a, kAutoFitter, trees);
    slot->tb = tree_for(sc.b, kAutoFitter, trees);
    for (const Pose& pose : sc.poses[scenario]) {
      const CollideTrace trace =
          collide_trace(*slot->ta, sc.a, Pose::identity(), *slot->tb, sc.b, pose,
                        {.mode = all_pairs ? QueryMode::all_pairs : QueryMode::first_hit}, {.max_pairs = 1u << 30});
      auto& tested = slot->tested.emplace_back();
      auto& leaves = slot->leaves.emplace_back();
      auto& descended = slot->descended.emplace_back();
      for (const VisitedPair& p : trace.pairs) {
        tested.push_back({p.a, p.b});
        if (p.outcome == PairOutcome::descended) descended.push_back({p.a, p.b});
        if (p.outcome == PairOutcome::leaves || p.outcome == PairOutcome::hit) leaves.push_back({p.a, p.b});
      }
    }
  }
  return *slot;
}

// Args: scenario, mode. The box tests of collide_trees: B's box mapped into A's frame once per
// query and node (the same cache), with the same allowance; the root pair alone, then each split
// pair's two children at once (boxes_overlap2), or its four when both nodes split
// (boxes_overlap_cross), as traverse_pairs_tested makes them. (A first_hit
// query also tests, never pops and never counts the children of its last splits; so does this.)
void BM_ReplayBoxTests(benchmark::State& state) {
  const Scene& sc = scene();
  const Recorded& rec = recorded(static_cast<int>(state.range(0)), state.range(1) != 0);
  const Tree& ta = *rec.ta;
  const Tree& tb = *rec.tb;
  query_detail::BoxCache cache;
  std::size_t tests = 0, overlaps = 0;
  const bool avx2 = query_detail::avx2_bounds_available();
  for (auto _ : state) {
    for (std::size_t q = 0; q < rec.tested.size(); ++q) {
      const Pose& rel = sc.poses[state.range(0)][q];  // A at identity: B's pose is the relative pose
      const double margin = query_detail::box_allowance(ta, tb, rel);
      cache.begin(tb.nodes.size());
      const auto mapped = [&](std::uint32_t ib) -> const query_detail::MappedBox& {
        return cache.mapped(ib, tb.nodes[ib].box, rel);
      };
      overlaps += query_detail::box_overlap(ta.nodes[0].box, mapped(0), tb.nodes[0].box.half_extents, margin);
      for (const query_detail::NodePair& p : rec.descended[q]) {
        const Node& na = ta.nodes[p.a];
        const Node& nb = tb.nodes[p.b];
        const query_detail::Split split = query_detail::choose_split(na, nb, DescendRule::larger_volume);
        if (query_detail::splits_both(split)) {
          const auto o = query_detail::boxes_overlap_cross(query_detail::child_boxes(ta, tb, na, nb, mapped),
                                                           split == query_detail::Split::both_a_first, margin, avx2);
          overlaps += o[0] + o[1] + o[2] + o[3];
          continue;
        }
        std::array<bool, 2> o;
        if (split == query_detail::Split::a)
          o = query_detail::boxes_overlap2(ta.nodes[na.first].box, mapped(p.b), nb.box.half_extents,
                                           ta.nodes[na.first + 1].box, mapped(p.b), nb.box.half_extents, margin);
        else
          o = query_detail::boxes_overlap2(na.box, mapped(nb.first), tb.nodes[nb.first].box.half_extents, na.box,
                                           mapped(nb.first + 1), tb.nodes[nb.first + 1].box.half_extents, margin);
        overlaps += o[0] + o[1];
      }
      tests += rec.tested[q].size();
    }
  }
  benchmark::DoNotOptimize(overlaps);
  state.SetItemsProcessed(static_cast<std::int64_t>(tests));
  state.SetLabel(std::string(kScenarioNames[state.range(0)]) + (state.range(1) ? "/all_pairs" : "/first_hit"));
}
BENCHMARK(BM_ReplayBoxTests)->ArgsProduct({{0, 1, 2}, {0, 1}})->ArgNames({"scenario", "all_pairs"});

// Args: scenario, mode. The leaf pairs' triangle tests as collide_trees makes them: B's
// triangles mapped into A's frame, then the exact test against each of A's; all_pairs queues
// them for the four-lane test where the CPU has AVX2 (tri_batch.hpp), as collide() does.
void BM_ReplayTriangleTests(benchmark::State& state) {
  const Scene& sc = scene();
  const bool all_pairs = state.range(1) != 0;
  const Recorded& rec = recorded(static_cast<int>(state.range(0)), all_pairs);
  const Tree& ta = *rec.ta;
  const Tree& tb = *rec.tb;
  const bool lanes = all_pairs && query_detail::avx2_bounds_available();
  std::size_t tests = 0, hits = 0;
  std::array<Vec3, 3> mapped;
  query_detail::TrianglePairBatch batch;
  QueryResult batched;
  for (auto _ : state) {
    for (std::size_t q = 0; q < rec.leaves.size(); ++q) {
      const Pose& rel = sc.poses[state.range(0)][q];
      for (const query_detail::NodePair& p : rec.leaves[q]) {
        const Node& na = ta.nodes[p.a];
        const Node& nb = tb.nodes[p.b];
        for (std::uint32_t j = 0; j < nb.count; ++j) {
          const Triangle& tri = sc.b.triangles[tb.triangle_order[nb.first + j]];
          for (int k = 0; k < 3; ++k) mapped[k] = query_detail::map_point(rel, sc.b.vertices[tri[k]]);
          for (std::uint32_t i = 0; i < na.count; ++i) {
            const Triangle& ta_tri = sc.a.triangles[ta.triangle_order[na.first + i]];
            const Vec3 &p0 = sc.a.vertices[ta_tri[0]], &p1 = sc.a.vertices[ta_tri[1]], &p2 = sc.a.vertices[ta_tri[2]];
            if (lanes)
              batch.add(p0, p1, p2, mapped[0], mapped[1], mapped[2], {i, j}, batched);
            else
              hits += tri_tri_overlap(p0, p1, p2, mapped[0], mapped[1], mapped[2]);
            ++tests;
          }
        }
      }
      batch.flush(batched);
      hits += batched.pairs.size();
      batched.pairs.clear();
    }
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(static_cast<std::int64_t>(tests));
  state.SetLabel(std::string(kScenarioNames[state.range(0)]) + (state.range(1) ? "/all_pairs" : "/first_hit"));
}
BENCHMARK(BM_ReplayTriangleTests)->ArgsProduct({{0, 1, 2}, {0, 1}})->ArgNames({"scenario", "all_pairs"});

// ---------------------------------------------------------------- wide float kernel (issue 38)

// The box-pair tests a descent over wide nodes makes (wide_nodes.hpp) on the auto trees, per pose
// of a scenario: each call tests one box against the four children of a node of the other tree.
// The descent keeps every pair the kernel keeps (all_pairs), splits the larger box by volume
// (B's when equal), stops at leaf pairs; a call whose box is B's (`swapped`) runs in the inverse
// frame. Recorded once with the full kernel; replayed below.
struct WideCall {
  bool swapped;                // the box is B's, the node A's
  std::int32_t box_node, node;  // the box is lane `lane` of wide node `box_node`
  int lane;
  Vec3 ref_box, ref_node;
  std::uint32_t src_box;       // the box's Tree node (for the double replay)
  std::uint32_t src_node[4];   // the node's lanes' Tree nodes; 0 when empty
};

struct WideRecorded {
  const Tree *ta = nullptr, *tb = nullptr;
  query_detail::WideTree wa, wb;
  std::vector<std::uint32_t> sa, sb;
  std::vector<std::vector<WideCall>> calls;  // per pose
  std::size_t lanes = 0;                     // non-empty lanes over all calls
};

double lane_volume(const query_detail::WideNode& n, int lane) {
  return static_cast<double>(n.half[0][lane]) * n.half[1][lane] * n.half[2][lane];
}

const WideRecorded& wide_recorded(int scenario) {
  static std::map<int, std::unique_ptr<WideRecorded>> cache;
  static std::map<std::pair<const Mesh*, int>, std::unique_ptr<Tree>> trees;
  auto& slot = cache[scenario];
  if (slot) return *slot;
  using namespace query_detail;
  const Scene& sc = scene();
  slot = std::make_unique<WideRecorded>();
  WideRecorded& rec = *slot;
  rec.ta = tree_for(sc.a, kAutoFitter, trees);
  rec.tb = tree_for(sc.b, kAutoFitter, trees);
  rec.wa = build_wide(*rec.ta, &rec.sa);
  rec.wb = build_wide(*rec.tb, &rec.sb);
  struct Pair {
    std::int32_t na, nb;  // A's box: lane la of na; B's box: lane lb of nb
    int la, lb;
    Vec3 ra, rb;          // refs of na and nb
  };
  for (const Pose& rel : sc.poses[scenario]) {
    const WideFrame fab = wide_frame(rel, rec.wa.eta, rec.wb.eta, 0.0);
    const WideFrame fba = wide_frame(rel.inverse(), rec.wb.eta, rec.wa.eta, 0.0);
    auto& calls = rec.calls.emplace_back();
    std::vector<Pair> stack;
    const auto call = [&](bool swapped, std::int32_t box_node, int lane, const Vec3& ref_box, std::int32_t node,
                          const Vec3& ref_node) {
      const WideTree& wbox = swapped ? rec.wb : rec.wa;
      const WideTree& wnode = swapped ? rec.wa : rec.wb;
      const auto& sbox = swapped ? rec.sb : rec.sa;
      const auto& snode = swapped ? rec.sa : rec.sb;
      WideCall c{swapped, box_node, node, lane, ref_box, ref_node, sbox[4 * box_node + lane], {}};
      for (int j = 0; j < kWideLanes; ++j) {
        c.src_node[j] = snode[4 * node + j];
        rec.lanes += !is_empty_lane(wnode.nodes[node], j);
      }
      calls.push_back(c);
      const WideFrame& f = swapped ? fba : fab;
      return wide_overlap(hoist(f, wide_pair(f, ref_box, ref_node), lane_box(wbox.nodes[box_node], lane)),
                          wnode.nodes[node]);
    };
    for (int i = 0; i < kWideLanes; ++i) {
      if (is_empty_lane(rec.wa.nodes[0], i)) continue;
      const unsigned kept = call(false, 0, i, rec.wa.root_ref, 0, rec.wb.root_ref);
      for (int j = 0; j < kWideLanes; ++j)
        if (kept >> j & 1u) stack.push_back({0, 0, i, j, rec.wa.root_ref, rec.wb.root_ref});
    }
    while (!stack.empty() && calls.size() < 20000) {
      const Pair p = stack.back();
      stack.pop_back();
      const WideNode& na = rec.wa.nodes[p.na];
      const WideNode& nb = rec.wb.nodes[p.nb];
      const bool a_internal = na.child[p.la] > 0, b_internal = nb.child[p.lb] > 0;
      if (!a_internal && !b_internal) continue;  // a leaf pair
      const Vec3 ca = child_ref(p.ra, na, p.la), cb = child_ref(p.rb, nb, p.lb);
      if (b_internal && (!a_internal || lane_volume(nb, p.lb) >= lane_volume(na, p.la))) {
        const unsigned kept = call(false, p.na, p.la, p.ra, nb.child[p.lb], cb);
        for (int j = 0; j < kWideLanes; ++j)
          if (kept >> j & 1u) stack.push_back({p.na, nb.child[p.lb], p.la, j, p.ra, cb});
      } else {
        const unsigned kept = call(true, p.nb, p.lb, p.rb, na.child[p.la], ca);
        for (int i = 0; i < kWideLanes; ++i)
          if (kept >> i & 1u) stack.push_back({na.child[p.la], p.nb, i, p.lb, ca, p.rb});
      }
    }
  }
  return rec;
}

std::size_t wide_calls(const WideRecorded& rec) {
  std::size_t n = 0;
  for (const auto& c : rec.calls) n += c.size();
  return n;
}

// Args: scenario, tier (0 faces only, 1 full). The float kernel on the recorded calls, each with
// its per-call setup: B's node ref in A's node frame (wide_pair, double), the box's lane loads and
// the hoisted rotation M = A^T R0 (hoist), then the four lanes. Items: non-empty box pairs.
void BM_WideBoxTests(benchmark::State& state) {
  using namespace query_detail;
  const Scene& sc = scene();
  const int scenario = static_cast<int>(state.range(0));
  const WideRecorded& rec = wide_recorded(scenario);
  std::vector<WideFrame> fab, fba;
  for (const Pose& rel : sc.poses[scenario]) {
    fab.push_back(wide_frame(rel, rec.wa.eta, rec.wb.eta, 0.0));
    fba.push_back(wide_frame(rel.inverse(), rec.wb.eta, rec.wa.eta, 0.0));
  }
  std::size_t kept = 0;
  for (auto _ : state) {
    for (std::size_t q = 0; q < rec.calls.size(); ++q)
      for (const WideCall& c : rec.calls[q]) {
        const WideFrame& f = c.swapped ? fba[q] : fab[q];
        const WideTree& wbox = c.swapped ? rec.wb : rec.wa;
        const WideTree& wnode = c.swapped ? rec.wa : rec.wb;
        const WideHoisted h = hoist(f, wide_pair(f, c.ref_box, c.ref_node), lane_box(wbox.nodes[c.box_node], c.lane));
        const unsigned m = state.range(1) == 0 ? wide_overlap<WideTier::faces>(h, wnode.nodes[c.node])
                                               : wide_overlap<WideTier::full>(h, wnode.nodes[c.node]);
        kept += static_cast<std::size_t>(__builtin_popcount(m));
      }
  }
  benchmark::DoNotOptimize(kept);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rec.lanes));
  state.counters["calls"] = static_cast<double>(wide_calls(rec));
  state.counters["pairs"] = static_cast<double>(rec.lanes);
  state.counters["B_per_tri"] = wide_bytes_per_triangle(rec.wa, sc.a.triangles.size());
  state.SetLabel(std::string(kScenarioNames[scenario]) + (state.range(1) ? "/full" : "/faces"));
}
BENCHMARK(BM_WideBoxTests)->ArgsProduct({{0, 1, 2}, {0, 1}})->ArgNames({"scenario", "tier"});

// Args: scenario, tier (0 faces, 1 full, 2 full in AVX2 pairs). The kernel alone: each call's hoisted box (wide_pair and hoist) computed
// before timing, so this is the four lanes' arithmetic and the node's loads.
void BM_WideKernelOnly(benchmark::State& state) {
  using namespace query_detail;
  const Scene& sc = scene();
  const int scenario = static_cast<int>(state.range(0));
  const WideRecorded& rec = wide_recorded(scenario);
  std::vector<WideHoisted> hoisted;
  std::vector<const WideNode*> nodes;
  for (std::size_t q = 0; q < rec.calls.size(); ++q) {
    const Pose& rel = sc.poses[scenario][q];
    const WideFrame fab = wide_frame(rel, rec.wa.eta, rec.wb.eta, 0.0);
    const WideFrame fba = wide_frame(rel.inverse(), rec.wb.eta, rec.wa.eta, 0.0);
    for (const WideCall& c : rec.calls[q]) {
      const WideFrame& f = c.swapped ? fba : fab;
      const WideTree& wbox = c.swapped ? rec.wb : rec.wa;
      const WideTree& wnode = c.swapped ? rec.wa : rec.wb;
      hoisted.push_back(hoist(f, wide_pair(f, c.ref_box, c.ref_node), lane_box(wbox.nodes[c.box_node], c.lane)));
      nodes.push_back(&wnode.nodes[c.node]);
    }
  }
  std::size_t kept = 0;
  const bool avx2 = avx2_bounds_available();
  if (state.range(1) == 2 && !avx2) {
    state.SkipWithError("no AVX2");
    return;
  }
  for (auto _ : state) {
    if (state.range(1) == 2) {  // consecutive calls two at a time in eight AVX2 lanes
      std::size_t i = 0;
      for (; i + 1 < hoisted.size(); i += 2)
        kept += static_cast<std::size_t>(
            __builtin_popcount(wide_overlap2(hoisted[i], *nodes[i], hoisted[i + 1], *nodes[i + 1], true)));
      if (i < hoisted.size()) kept += static_cast<std::size_t>(__builtin_popcount(wide_overlap(hoisted[i], *nodes[i])));
      continue;
    }
    for (std::size_t i = 0; i < hoisted.size(); ++i) {
      const unsigned m = state.range(1) == 0 ? wide_overlap<WideTier::faces>(hoisted[i], *nodes[i])
                                             : wide_overlap<WideTier::full>(hoisted[i], *nodes[i]);
      kept += static_cast<std::size_t>(__builtin_popcount(m));
    }
  }
  benchmark::DoNotOptimize(kept);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rec.lanes));
  state.counters["kept"] = static_cast<double>(kept) / static_cast<double>(state.iterations());
  state.SetLabel(std::string(kScenarioNames[scenario]) +
                 (state.range(1) == 2 ? "/full-avx2x8" : state.range(1) ? "/full" : "/faces"));
}
// tier 2: the full kernel, two calls at once in eight AVX2 lanes (wide_overlap2).
BENCHMARK(BM_WideKernelOnly)->ArgsProduct({{0, 1, 2}, {0, 1, 2}})->ArgNames({"scenario", "tier"});

// Args: scenario. The full kernel with the per-box hoist (M = A^T R0, A's offsets) timed and the
// node pair's frame (wide_pair, double) and A's lane gather done before: what a call costs when a
// descent carries B's node offset along instead of recomputing it in double.
void BM_WideHoistAndKernel(benchmark::State& state) {
  using namespace query_detail;
  const Scene& sc = scene();
  const int scenario = static_cast<int>(state.range(0));
  const WideRecorded& rec = wide_recorded(scenario);
  struct Prepared {
    const WideFrame* f;
    WidePair pair;
    WideBox box;
    const WideNode* node;
  };
  std::vector<WideFrame> frames;
  frames.reserve(2 * rec.calls.size());
  std::vector<Prepared> prepared;
  for (std::size_t q = 0; q < rec.calls.size(); ++q) {
    const Pose& rel = sc.poses[scenario][q];
    frames.push_back(wide_frame(rel, rec.wa.eta, rec.wb.eta, 0.0));
    frames.push_back(wide_frame(rel.inverse(), rec.wb.eta, rec.wa.eta, 0.0));
    for (const WideCall& c : rec.calls[q]) {
      const WideFrame& f = frames[2 * q + (c.swapped ? 1 : 0)];
      const WideTree& wbox = c.swapped ? rec.wb : rec.wa;
      const WideTree& wnode = c.swapped ? rec.wa : rec.wb;
      prepared.push_back({&f, wide_pair(f, c.ref_box, c.ref_node), lane_box(wbox.nodes[c.box_node], c.lane),
                          &wnode.nodes[c.node]});
    }
  }
  std::size_t kept = 0;
  for (auto _ : state)
    for (const Prepared& p : prepared)
      kept += static_cast<std::size_t>(__builtin_popcount(wide_overlap(hoist(*p.f, p.pair, p.box), *p.node)));
  benchmark::DoNotOptimize(kept);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rec.lanes));
  state.SetLabel(kScenarioNames[scenario]);
}
BENCHMARK(BM_WideHoistAndKernel)->DenseRange(0, 2)->ArgName("scenario");

// Args: scenario. Today's double kernel on the same box pairs: the Tree's boxes, the other tree's
// mapped into the box's frame through the per-query cache (as collide() does), two pairs per
// call of the two-lane SSE2 test (boxes_overlap2), with collide()'s allowance as the margin.
void BM_WideCallsDoubleKernel(benchmark::State& state) {
  using namespace query_detail;
  const Scene& sc = scene();
  const int scenario = static_cast<int>(state.range(0));
  const WideRecorded& rec = wide_recorded(scenario);
  const Tree& ta = *rec.ta;
  const Tree& tb = *rec.tb;
  BoxCache cab, cba;
  std::size_t kept = 0;
  for (auto _ : state) {
    for (std::size_t q = 0; q < rec.calls.size(); ++q) {
      const Pose& rel = sc.poses[scenario][q];
      const Pose inv = rel.inverse();
      const double margin = box_allowance(ta, tb, rel);
      cab.begin(tb.nodes.size());
      cba.begin(ta.nodes.size());
      for (const WideCall& c : rec.calls[q]) {
        const Tree& tbox = c.swapped ? tb : ta;
        const Tree& tnode = c.swapped ? ta : tb;
        BoxCache& cache = c.swapped ? cba : cab;
        const Pose& p = c.swapped ? inv : rel;
        const CompactBox& a = tbox.nodes[c.src_box].box;
        for (int j = 0; j < kWideLanes; j += 2) {
          if (c.src_node[j] == 0) break;
          const std::uint32_t j1 = c.src_node[j + 1] == 0 ? c.src_node[j] : c.src_node[j + 1];
          const auto o = boxes_overlap2(a, cache.mapped(c.src_node[j], tnode.nodes[c.src_node[j]].box, p),
                                        tnode.nodes[c.src_node[j]].box.half_extents, a,
                                        cache.mapped(j1, tnode.nodes[j1].box, p), tnode.nodes[j1].box.half_extents,
                                        margin);
          kept += o[0] + o[1];
        }
      }
    }
  }
  benchmark::DoNotOptimize(kept);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rec.lanes));
  state.SetLabel(kScenarioNames[scenario]);
}
BENCHMARK(BM_WideCallsDoubleKernel)->DenseRange(0, 2)->ArgName("scenario");

// ---------------------------------------------------------------- wide descent (issue 38)

// Queries per second of the descent over wide trees (collide_wide, src/collide/wide_collide.hpp)
// against collide() on the same auto trees and poses. Args: engine (0 collide() with a reused
// workspace, 1 collide_wide, 2 collide_wide without swapped tests; adjacent in the run, so that
// all see the same machine), scenario,
// mode (0 first_hit, 1 all_pairs). Counters as
// BM_Traversal's; box_tests count box pairs (a kernel lane for collide_wide).
void BM_WideCollide(benchmark::State& state) {
  static std::map<std::pair<const Mesh*, int>, std::unique_ptr<Tree>> trees;
  static std::map<const Tree*, query_detail::WideTree> wides;
  const Scene& sc = scene();
  const Tree* ta = tree_for(sc.a, kAutoFitter, trees);
  const Tree* tb = tree_for(sc.b, kAutoFitter, trees);
  for (const Tree* t : {ta, tb})
    if (!wides.contains(t)) wides.emplace(t, query_detail::build_wide(*t));
  const query_detail::WideTree& wa = wides.at(ta);
  const query_detail::WideTree& wb = wides.at(tb);
  const bool wide = state.range(0) != 0;
  const bool swap = state.range(0) != 2;
  const int scenario = static_cast<int>(state.range(1));
  const bool all_pairs = state.range(2) != 0;
  const QueryMode mode = all_pairs ? QueryMode::all_pairs : QueryMode::first_hit;
  const QueryOptions options{.mode = mode};
  QueryWorkspace workspace;
  QueryStats total;
  query_detail::WideCounters counters;
  std::size_t queries = 0, hits = 0, pairs = 0;
  for (auto _ : state) {
    for (const Pose& pose : sc.poses[scenario]) {
      const QueryResult r = wide ? query_detail::collide_wide(*ta, wa, sc.a, *tb, wb, sc.b, pose, mode, 0.0, &counters, swap)
                                 : collide(*ta, sc.a, Pose::identity(), *tb, sc.b, pose, options, workspace);
      total.box_tests += r.stats.box_tests;
      total.triangle_tests += r.stats.triangle_tests;
      hits += r.hit;
      pairs += r.pairs.size();
      ++queries;
    }
  }
  const double q = static_cast<double>(queries);
  state.counters["box_tests"] = static_cast<double>(total.box_tests) / q;
  state.counters["tri_tests"] = static_cast<double>(total.triangle_tests) / q;
  // Four-lane kernel calls per query (collide_wide only; box_tests / kernel_calls = lanes per call).
  state.counters["kernel_calls"] = static_cast<double>(counters.kernel_calls) / q;
  state.counters["hit_rate"] = static_cast<double>(hits) / q;
  state.counters["pairs"] = static_cast<double>(pairs) / q;
  state.counters["queries_per_s"] = benchmark::Counter(q, benchmark::Counter::kIsRate);
  state.SetLabel(std::string(kScenarioNames[scenario]) + "/" + (all_pairs ? "all_pairs" : "first_hit") + "/" +
                 (wide ? (swap ? "collide_wide" : "collide_wide_noswap") : "collide"));
}
BENCHMARK(BM_WideCollide)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}, {0, 1}})
    ->ArgNames({"wide", "scenario", "all_pairs"})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
