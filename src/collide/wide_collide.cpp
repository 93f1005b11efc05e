// collide's descent over two wide trees: a hoisted box of A descends B with B's reference point
// moved in float. See wide_collide.hpp.
#include "wide_collide.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>

#include "box_bounds4.hpp"
#include "box_test.hpp"
#include "pair_sort.hpp"
#include "query_common.hpp"
#include "tightbvh/tri_tri.hpp"
#include "tri_batch.hpp"

namespace tightbvh::query_detail {
namespace {

constexpr double kU = 0x1p-24;  // float's unit roundoff

// A float >= x for x >= 0 below float's overflow (as wide_pair rounds t_err up): the factor
// puts float(x') >= x' (1 - 2^-24) > x, and 1e-30 keeps x' in float's normal range.
float up(double x) { return static_cast<float>(x * (1.0 + 0x1p-20) + 1e-30); }

}  // namespace

// The four boxes of A's node n hoisted at once, each lane as hoist (wide_nodes.hpp) computes it for
// the box in that lane, operation for operation: M = A^T fl(R0), d = t - ca, tn = A^T d, and the
// base allowance kappa (sum ea + margin) + 10 u |d|_1 + 4 t_err + margin. tn is within
// 4.8 u |d|_1 + 1.75 t_err of exact (the allowance section of wide_nodes.hpp); that bound is
// evaluated in float, a few sums and products of nonnegative terms whose rounding (< 5 u relative)
// the factor 1 + 2^-20 = 1 + 16 u covers, so err >= the bound.
HoistedNode hoist_node(const WideFrame& f, const WideNode& n, const float (&t)[3], double t_err) {
  HoistedNode hn;
  hn.node = &n;
  hn.k.kappa = f.kappa;
  const float tf_err = up(t_err);
  F4 ax[9];
  for (int r = 0; r < 9; ++r) ax[r] = load4(n.axes[r]);
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      store4(hn.k.m[3 * i + k],
             ax[3 * i] * splat4(f.r0[k]) + ax[3 * i + 1] * splat4(f.r0[3 + k]) + ax[3 * i + 2] * splat4(f.r0[6 + k]));
  F4 d[3], e[3];
  for (int k = 0; k < 3; ++k) {
    d[k] = splat4(t[k]) - load4(n.center[k]);
    e[k] = load4(n.half[k]);
    store4(hn.k.ea[k], e[k]);
  }
  for (int i = 0; i < 3; ++i) store4(hn.tn[i], ax[3 * i] * d[0] + ax[3 * i + 1] * d[1] + ax[3 * i + 2] * d[2]);
  const F4 d1 = lane_abs(d[0]) + lane_abs(d[1]) + lane_abs(d[2]);
  const F4 kappa = splat4(f.kappa), margin = splat4(f.margin);
  const F4 scaled = kappa * (e[0] + e[1] + e[2] + margin);
  store4(hn.base, scaled + splat4(10.0f * kUnitRoundoff) * d1 + splat4(4.0f) * splat4(tf_err) + margin);
  store4(hn.core, scaled + margin);
  store4(hn.volume, e[0] * e[1] * e[2]);
  store4(hn.err, (splat4(4.8f * kUnitRoundoff) * d1 + splat4(1.75f) * splat4(tf_err)) * splat4(1.0f + 0x1p-20f));
  return hn;
}

// The moved reference point. x is hoisted for B's node whose ref is ref_b; the same box of A
// against B's child node at ref_c = ref_b (+) c (child_ref: double additions of the child's float
// offset c) needs tn_c = A^T (R0 ref_c + t0 - ref_a - ca) = tn + A^T R0 c + A^T R0 (ref_c - ref_b - c).
// It is computed as tn' = fl(tn + fl(M c)), with M = fl(A^T fl(R0)) the hoisted matrix:
//   - |M_ik - (A^T R0)_ik| <= 4.1 u (wide_nodes.hpp), so |(M - A^T R0) c| <= 4.1 u |c|_1;
//   - the float dot product M c: gamma_3 sum |M_ik c_k| <= 3.0001 u 1.02 |c|_1 = 3.07 u |c|_1;
//   - the final addition: u |tn + fl(M c)| <= 1.0001 u |tn'|;
//   - ref_c - ref_b - c: each double addition rounds by 2^-53 |ref_c,k|, and A^T R0 stretches a
//     vector by at most (1 + eta)(1 + |R0^T R0 - I|) < 1.01 in each component of the 1-norm:
//     <= 1.01 2^-53 |ref_c|_1 <= 1.01 2^-53 ref_bound (WideTree::ref_bound: the descent needs no
//     ref itself, only this bound on how its rounding moves B's node);
// so err' = err + 7.5 u |c|_1 + 1.01 u |tn'|_inf + ref_round, ref_round = 1.1 2^-53 ref_bound
// (>= 1.1 2^-53 |ref_c|_1; every term computed in double, the
// (1 + 2^-50) factor covering its rounding). The kernel needs its tn within err of exact with
// base >= the rest of its allowance + 1.8 err (the allowance section: tn's error reaches each
// axis' offset through weights summing to <= 1.8), so base' = core + up(2 err'); the float sum
// can round it down by u relative, which the 2 against 1.8 covers.
void move_b(DescentBox& x, const WideNode& n, int lane, double ref_round, const float (&f_r0)[9]) {
  const float c[3] = {n.center[0][lane], n.center[1][lane], n.center[2][lane]};
  const float(&m)[9][kWideLanes] = x.hn->k.m;
  const int a = x.lane;
  float tinf = 0.0f;
  for (int i = 0; i < 3; ++i) {
    x.tn[i] = x.tn[i] + (m[3 * i][a] * c[0] + m[3 * i + 1][a] * c[1] + m[3 * i + 2][a] * c[2]);
    tinf = std::max(tinf, std::abs(x.tn[i]));
  }
  const double c1 = std::abs(static_cast<double>(c[0])) + std::abs(static_cast<double>(c[1])) +
                    std::abs(static_cast<double>(c[2]));
  x.err = (x.err + 7.5 * kU * c1 + 1.01 * kU * static_cast<double>(tinf) + ref_round) * (1.0 + 0x1p-50);
  x.base = x.hn->core[a] + up(2.0 * x.err);
  // B's ref in the frame of A's node, for the boxes of A's side (fresh): t' = fl(t + fl(R0f c)),
  // exact t + R0 c + R0 (ref_c - ref_b - c). With R0f = fl(R0) (entries within u of R0's,
  // |R0_ij| <= 1.0001): |(R0f - R0) c| <= 1.0001 u |c|_1, the dot product gamma_3 1.0001 |c|_1,
  // the addition 1.0001 u |t'|_inf, the refs' rounding 1.01 2^-53 |ref_c|_1 <= ref_round (as above).
  float t_inf = 0.0f;
  for (int k = 0; k < 3; ++k) {
    x.t[k] = x.t[k] + (f_r0[3 * k] * c[0] + f_r0[3 * k + 1] * c[1] + f_r0[3 * k + 2] * c[2]);
    t_inf = std::max(t_inf, std::abs(x.t[k]));
  }
  x.t_err = (x.t_err + 4.5 * kU * c1 + 1.01 * kU * static_cast<double>(t_inf) + ref_round) * (1.0 + 0x1p-50);
}

// B's ref in the frame of the child node of A's box x (ref ref_c = ref_a (+) c, c the box's
// float offset), from x.t: t' = fl(t - c), exact t - c - (ref_c - ref_a - c): the subtraction
// rounds by 1.0001 u |t'|_inf, the refs' double additions by 2^-53 |ref_c|_1 <= ref_round (A's
// tree's, as in move_b).
void move_a(const DescentBox& x, double ref_round, float (&t)[3], double& t_err) {
  float t_inf = 0.0f;
  for (int k = 0; k < 3; ++k) {
    t[k] = x.t[k] - x.node().center[k][x.lane];
    t_inf = std::max(t_inf, std::abs(t[k]));
  }
  t_err = (x.t_err + 1.01 * kU * static_cast<double>(t_inf) + ref_round) * (1.0 + 0x1p-50);
}

double ref_round(const WideTree& tree) { return 1.1 * 0x1p-53 * tree.ref_bound * (1.0 + 0x1p-50); }

// A's node ref in the frame of B's node under the swapped frame (wide_frame_swapped: P' = (R0^T,
// t0'), t0' = -R0^T t0 rounded in double), from t = B's node ref in A's node frame:
//   s* = R0^T ref_a + t0' - ref_b = -R0^T t* + (R0^T R0 - I) ref_b + (t0' + R0^T t0),
// t* = R0 ref_b + t0 - ref_a the exact t. It is computed as s = -fl(fl(R0)^T t), within
//   |R0^T (t - t*)|_inf <= 1.74 t_err (a column of R0 has 1-norm <= sqrt(3)(1 + e0)),
//   |(fl(R0) - R0)^T t|_inf + the float dot product <= u 1.0001 |t|_1 + gamma_3 1.0002 |t|_1
//                                                  <= 4.01 u |t|_1,
// of -R0^T t*; the other two terms are <= 3 e0 |ref_b|_inf <= swap_rel ref_bound and <= swap_abs
// (wide_nodes.cpp), which `fixed` must cover.
void swap_point(const float (&r0)[9], const float (&t)[3], double t_err, double fixed, float (&s)[3], double& s_err) {
  for (int k = 0; k < 3; ++k) s[k] = -(r0[k] * t[0] + r0[3 + k] * t[1] + r0[6 + k] * t[2]);
  const double t1 = std::abs(static_cast<double>(t[0])) + std::abs(static_cast<double>(t[1])) +
                    std::abs(static_cast<double>(t[2]));
  s_err = (1.74 * t_err + 4.01 * kU * t1 + fixed) * (1.0 + 0x1p-50);
}

// The descent's float errors bounded once per query, by summing the steps' bounds (move_b,
// move_a, hoist_node's) over any path, so that the descent itself carries no error:
//   - every pair of nodes has |t*|_inf <= x = |t_root|_inf + t_root_err + 1.01 spread_B +
//     spread_A (t* = t_root* + R0 (ref_b - root_b) - (ref_a - root_a), |R0 v|_inf <= 1.01 |v|_1);
//   - t moves down B at most depth_B times, with offsets summing to <= path_B, and down A at most
//     depth_A times, each step adding <= 1.01 u |t'|_inf <= 1.01 u t_max (t_max = x + t_err) and
//     its tree's ref_round: t_err = root_err + 4.5 u path_B + depth_B round_B + depth_A round_A
//     + k t_max, k = 1.01 u (depth_A + depth_B), solved as (y + k x) / (1 - k);
//   - a box of A hoisted anywhere has tn within 4.8 u |d|_1 + 1.75 t_err (|d|_1 <= 3.001 (t_max +
//     offset_A), offset_A >= |ca|_1), and each of its at most depth_B moves down B adds
//     7.5 u |c|_1 (summing to <= 7.5 u path_B), round_B and 1.01 u |tn'|_inf, with |tn'|_inf <=
//     1.7323 (t_max + offset_A) + err (|a_i . v| <= (1 + eta) sqrt(3) |v|_inf): err = c + q tn_max,
//     q = 1.01 u depth_B, solved likewise.
// 1 / (1 - k) <= 1 + 2k for 0 <= k <= 1/2: a multiplication where k <= 1/4 (any tree of fewer than
// four million levels), the division otherwise.
// The kernel's base for a forward box is then core + up(2 err), as move_b sets it from its own err.
DescentBounds descent_bounds(const WideTree& wa, const WideTree& wb, const WidePair& root) {
  constexpr double kUp = 1.0 + 0x1p-50;
  const double root_err = static_cast<double>(root.t_err);
  double rt = 0.0;
  for (const float v : root.t) rt = std::max(rt, std::abs(static_cast<double>(v)));
  const double x = (rt + root_err + 1.01 * wb.spread + wa.spread) * kUp;
  const double k = 1.01 * kU * static_cast<double>(wa.depth + wb.depth);
  const double y = root_err + 4.5 * kU * wb.path_bound + wb.depth * ref_round(wb) + wa.depth * ref_round(wa);
  DescentBounds b;
  const auto over_one_minus = [](double v, double k) { return k <= 0.25 ? v * (1.0 + 2.0 * k) : v / (1.0 - k); };
  b.t_err = over_one_minus(y + k * x, k) * kUp * kUp;
  const double reach = (x + b.t_err + wa.offset_bound) * kUp;
  const double q = 1.01 * kU * static_cast<double>(wb.depth);
  const double c = 4.8 * kU * 3.001 * reach + 1.75 * b.t_err + 7.5 * kU * wb.path_bound + wb.depth * ref_round(wb);
  b.err = over_one_minus(c + q * 1.7323 * reach, q) * kUp * kUp;
  return b;
}

namespace {

// first_hit visits a step's boxes nearest first (as traverse.hpp orders a split's child pairs):
// `order` gets 0..count-1 sorted by |tn|_1, the distance from A's box center to B's node ref (a
// node's ref is its box's center) in A's box frame.
void nearest_first(const DescentBox* boxes, int count, int (&order)[kWideLanes]) {
  float key[kWideLanes];
  for (int k = 0; k < count; ++k) {
    key[k] = std::abs(boxes[k].tn[0]) + std::abs(boxes[k].tn[1]) + std::abs(boxes[k].tn[2]);
    int i = k;
    for (; i > 0 && key[order[i - 1]] > key[k]; --i) order[i] = order[i - 1];
    order[i] = k;
  }
}

// The lanes set in a four-lane mask (std::popcount is a library call on x86-64 without POPCNT).
int lanes_in(unsigned mask) { return (0x4332322132212110ull >> (4 * (mask & 0xFu))) & 0xF; }

// For each four-lane mask, its bits spread four apart (bit i to bit 4 i): a column of a 4 x 4
// bit matrix.
constexpr std::array<std::uint16_t, 16> kSpread = [] {
  std::array<std::uint16_t, 16> spread{};
  for (unsigned mask = 0; mask < 16; ++mask)
    for (unsigned i = 0; i < 4; ++i) spread[mask] |= static_cast<std::uint16_t>(((mask >> i) & 1u) << (4 * i));
  return spread;
}();

// For each four-lane mask, its set lanes in increasing order, two bits each (lanes_in of them).
constexpr std::array<std::uint8_t, 16> kLaneLists = [] {
  std::array<std::uint8_t, 16> lists{};
  for (unsigned mask = 0; mask < 16; ++mask) {
    unsigned packed = 0, count = 0;
    for (unsigned lane = 0; lane < 4; ++lane)
      if ((mask >> lane) & 1u) packed |= lane << (2 * count++);
    lists[mask] = static_cast<std::uint8_t>(packed);
  }
  return lists;
}();

// move_b without its error bounds, which descent_bounds covers for the whole query (the descent's
// move of A's side, t - c, is written where it is made).
[[gnu::always_inline]] inline void move_b_fast(DescentBox& x, const WideNode& n, int lane, const float (&f_r0)[9]) {
  const float c[3] = {n.center[0][lane], n.center[1][lane], n.center[2][lane]};
  const float(&m)[9][kWideLanes] = x.hn->k.m;
  const int a = x.lane;
  for (int i = 0; i < 3; ++i) {
    x.tn[i] = x.tn[i] + (m[3 * i][a] * c[0] + m[3 * i + 1][a] * c[1] + m[3 * i + 2][a] * c[2]);
    x.t[i] = x.t[i] + (f_r0[3 * i] * c[0] + f_r0[3 * i + 1] * c[1] + f_r0[3 * i + 2] * c[2]);
  }
}

// The lanes of n that hold a child (is_empty_lane's test on all four at once).
unsigned occupied(const WideNode& n) {
#ifdef TIGHTBVH_WIDE_SSE
  const __m128i child = _mm_load_si128(reinterpret_cast<const __m128i*>(n.child));
  return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(child, _mm_setzero_si128())))) ^ 0xFu;
#else
  unsigned m = 0;
  for (int l = 0; l < kWideLanes; ++l) m |= static_cast<unsigned>(!is_empty_lane(n, l)) << l;
  return m;
#endif
}

// The lanes of n that hold a leaf (child reference < 0): their sign bits.
unsigned leaf_lanes(const WideNode& n) {
#ifdef TIGHTBVH_WIDE_SSE
  return static_cast<unsigned>(_mm_movemask_ps(_mm_load_ps(reinterpret_cast<const float*>(n.child))));
#else
  unsigned m = 0;
  for (int l = 0; l < kWideLanes; ++l) m |= static_cast<unsigned>(n.child[l] < 0) << l;
  return m;
#endif
}

// The lanes of n whose box's volume (e_0 e_1 e_2, in float, in that order) is >= volume: the
// same products and comparisons as one lane at a time.
unsigned lanes_at_least(const WideNode& n, float volume) {
#ifdef TIGHTBVH_WIDE_SSE
  const __m128 v = _mm_mul_ps(_mm_mul_ps(_mm_load_ps(n.half[0]), _mm_load_ps(n.half[1])), _mm_load_ps(n.half[2]));
  return static_cast<unsigned>(_mm_movemask_ps(_mm_cmpge_ps(v, _mm_set1_ps(volume))));
#else
  unsigned m = 0;
  for (int l = 0; l < kWideLanes; ++l)
    m |= static_cast<unsigned>(n.half[0][l] * n.half[1][l] * n.half[2][l] >= volume) << l;
  return m;
#endif
}

template <bool FirstHit, bool Traced = false>
struct Descent {
  const Tree& ta;
  const WideTree& wa;
  const Mesh& ma;
  const Tree& tb;
  const WideTree& wb;
  const Mesh& mb;
  const Pose& rel;
  WideFrame f;
  WideFrame fs;             // the swapped frame (wide_frame_swapped)
  double swap_fixed;        // swap_point's `fixed` for B's tree: fs.swap_rel ref_bound + fs.swap_abs
  double swap_hoist;        // swap_error of any box of B: fs.swap_rel reach_bound + fs.swap_abs
  bool swap;                // test A's side with the roles swapped where that makes fewer calls
  bool avx2;
  QueryResult& result;
  // The leaves' scratch, the caller's locals: members of this aggregate would be value-initialised,
  // zeroing their 2.9 KB on every query (a quarter of the setup of a query that stops early).
  TrianglePairBatch& batch;
  MappedChunk& mapped;
  std::uint64_t box_tests = 0, triangle_tests = 0, kernel_calls = 0;
  double t_err_q = 0.0;  // descent_bounds: t's error anywhere in the descent
  float base_add = 0.0f;  // up(2 err) of descent_bounds: a forward box's base is its core plus this
  double margin = 0.0;    // > 0: the leaves report pairs within it (within_margin), as collide() does
  WideTraceSink* sink = nullptr;  // Traced: where the tests are recorded
  // all_pairs: a forward test (a box of A against a node of B) that came alone and waits for a
  // partner, so that the eight-lane kernel runs full; single calls were half of an overlap
  // query's kernel calls. Its box's hoisted node belongs to a descend_a frame still live:
  // descend_a tests what waits on its own node before it returns. first_hit keeps its order.
  struct Waiting {
    DescentBox x{};
    std::int32_t nb = 0;
    bool full = false;
  } waiting{};

  // Traced: the tests of the box in lane a_lane of A's node a against the lanes `lanes` of B's node
  // nb, `kept` the lanes kept; a kept pair of two leaves is remembered for its triangles' outcome.
  void record(const WideNode& a, int a_lane, std::int32_t nb, unsigned lanes, unsigned kept) {
    if constexpr (Traced) {
      const auto a_node = static_cast<std::uint32_t>(&a - wa.nodes.data());
      const WideNode& n = wb.nodes[static_cast<std::size_t>(nb)];
      for (unsigned m = lanes; m != 0; m &= m - 1) {
        const int l = std::countr_zero(m);
        const bool keep = ((kept >> l) & 1u) != 0;
        const bool two_leaves = keep && a.child[a_lane] < 0 && n.child[l] < 0;
        const auto b_node = static_cast<std::uint32_t>(nb);
        if (two_leaves) sink->leaf_tests[WideTraceSink::key(a_node, a_lane, b_node, l)] = sink->tests.size();
        const PairOutcome outcome =
            !keep ? PairOutcome::culled : two_leaves ? PairOutcome::leaves : PairOutcome::descended;
        sink->tests.push_back(
            {a_node, b_node, static_cast<std::uint8_t>(a_lane), static_cast<std::uint8_t>(l), outcome});
      }
    } else {
      (void)a, (void)a_lane, (void)nb, (void)lanes, (void)kept;
    }
  }

  // The triangle pairs of A's leaf ca and B's leaf cb (child references),
  // in collide()'s order: B's triangles mapped into A's frame a chunk at a time. True: stop.
  bool leaves(std::int32_t ca, std::int32_t cb) {
    const auto [fa, na] = wa.leaf(ca);
    const auto [fb, nb] = wb.leaf(cb);
    for (std::uint32_t c = 0; c < nb; c += kLeafChunk) {
      const std::uint32_t n = std::min(kLeafChunk, nb - c);
      for (std::uint32_t j = 0; j < n; ++j) {
        const Triangle& tri = mb.triangles[tb.triangle_order[fb + c + j]];
        for (int k = 0; k < 3; ++k) mapped[j][k] = map_point(rel, mb.vertices[tri[k]]);
      }
      for (std::uint32_t i = 0; i < na; ++i) {
        const std::uint32_t ia = ta.triangle_order[fa + i];
        const Triangle& tri = ma.triangles[ia];
        const Vec3& p0 = ma.vertices[tri[0]];
        const Vec3& p1 = ma.vertices[tri[1]];
        const Vec3& p2 = ma.vertices[tri[2]];
        for (std::uint32_t j = 0; j < n; ++j) {
          ++triangle_tests;
          const TrianglePair ids{ia, tb.triangle_order[fb + c + j]};
          if constexpr (!FirstHit) {
            if (avx2 && margin == 0.0 && !Traced) {
              batch.add(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2], ids, result);
              continue;
            }
          }
          if (margin > 0.0 ? within_margin(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2], margin)
                           : tri_tri_overlap(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2])) {
            result.hit = true;
            result.pairs.push_back(ids);
            if constexpr (FirstHit) return true;
          }
        }
      }
    }
    return false;
  }

  // One test of view v against node b, in one eight-lane call with the waiting forward test if
  // there is one (which is then taken: `taken` and its lanes kept, for the caller to visit after
  // its own test). Returns v's lanes kept.
  unsigned single(const WideBoxView& v, const WideNode& b, Waiting& taken, unsigned& taken_kept) {
    if (FirstHit || !waiting.full) {
      ++kernel_calls;
      return wide_overlap(v, b);
    }
    taken = waiting;
    waiting.full = false;
    const WideNode& tb_node = wb.nodes[static_cast<std::size_t>(taken.nb)];
    box_tests += lanes_in(occupied(tb_node));
    kernel_calls += 2;
    const unsigned both = wide_overlap2(v, b, taken.x.view(), tb_node, avx2);
    taken_kept = both >> 4;
    record(taken.x.node(), taken.x.lane, taken.nb, occupied(tb_node), taken_kept);
    return both & 0xFu;
  }

  // The waiting test, taken by single(): its descents.
  void visit_taken(const Waiting& taken, unsigned kept) {
    if (taken.full && kept != 0) (void)visit(taken.x, taken.nb, kept);
  }

  // Tests alone what waits on the hoisted node hn, before the frame holding hn returns.
  void flush_waiting(const HoistedNode& hn) {
    while (waiting.full && waiting.x.hn == &hn) {
      const Waiting w = waiting;
      waiting.full = false;
      const WideNode& b = wb.nodes[static_cast<std::size_t>(w.nb)];
      box_tests += lanes_in(occupied(b));
      ++kernel_calls;
      const unsigned kept = wide_overlap(w.x.view(), b);
      record(w.x.node(), w.x.lane, w.nb, occupied(b), kept);
      if (kept != 0) (void)visit(w.x, w.nb, kept);
    }
  }

  // Box x of A against B's node nb, whose lanes `kept` the kernel kept. True: stop.
  bool visit(const DescentBox& x, std::int32_t nb, unsigned kept) {
    const WideNode& n = wb.nodes[static_cast<std::size_t>(nb)];
    const std::int32_t a_child = x.node().child[x.lane];
    const float a_volume = x.hn->volume[x.lane];
    // The kept lanes sorted by where they lead, a mask each, rather than branch by branch: which
    // lane is a leaf, which box is the larger and whether x is a leaf are coin flips for the
    // branch predictor. leaves_b: pairs of leaves; down_b: lanes of n to descend with x (all
    // internal ones when x is a leaf); down_a: lanes met by the children of x.
    const unsigned a_leaf = 0u - static_cast<unsigned>(a_child < 0);  // all bits when x is a leaf
    const unsigned internal_b = kept & ~leaf_lanes(n);
    const unsigned leaves_b = kept & ~internal_b & a_leaf;
    const unsigned down_b = internal_b & (lanes_at_least(n, a_volume) | a_leaf);
    const unsigned down_a = kept & ~down_b & ~a_leaf;
    DescentBox moved[kWideLanes];
    std::int32_t next[kWideLanes];
    int moves = 0;
    for (unsigned m = leaves_b; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      const std::size_t reported = result.pairs.size();
      const bool stop = leaves(a_child, n.child[lane]);
      if constexpr (Traced) {
        if (result.pairs.size() > reported)
          sink->mark_hit(static_cast<std::uint32_t>(&x.node() - wa.nodes.data()), x.lane,
                         static_cast<std::uint32_t>(nb), lane);
      }
      if (stop) return true;
    }
    for (unsigned m = down_b; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      next[moves] = n.child[lane];
      moved[moves] = x;
      move_b_fast(moved[moves], n, lane, f.r0);
      ++moves;
    }
    int order[kWideLanes] = {0, 1, 2, 3};
    if constexpr (FirstHit) nearest_first(moved, moves, order);
    // Two nodes per kernel call in the visiting order, each pair tested just before its descents,
    // so that first_hit stopping below the first pair spares the second pair's call.
    for (int i = 0; i < moves; i += 2) {
      const int k0 = order[i], k1 = i + 1 < moves ? order[i + 1] : -1;
      if (!FirstHit && k1 < 0 && !waiting.full) {  // alone: waits for a partner
        waiting = {moved[k0], next[k0], true};
        break;
      }
      const WideNode& b0 = wb.nodes[static_cast<std::size_t>(next[k0])];
      box_tests += lanes_in(occupied(b0));
      unsigned m0 = 0, m1 = 0;
      Waiting taken;
      unsigned taken_kept = 0;
      if (k1 >= 0) {
        const WideNode& b1 = wb.nodes[static_cast<std::size_t>(next[k1])];
        box_tests += lanes_in(occupied(b1));
        kernel_calls += 2;
        const unsigned both = wide_overlap2(moved[k0].view(), b0, moved[k1].view(), b1, avx2);
        m0 = both & 0xFu;
        m1 = both >> 4;
      } else {
        m0 = single(moved[k0].view(), b0, taken, taken_kept);
      }
      if constexpr (Traced) {
        record(moved[k0].node(), moved[k0].lane, next[k0], occupied(b0), m0);
        if (k1 >= 0) {
          const WideNode& b1 = wb.nodes[static_cast<std::size_t>(next[k1])];
          record(moved[k1].node(), moved[k1].lane, next[k1], occupied(b1), m1);
        }
      }
      if (m0 != 0 && visit(moved[k0], next[k0], m0)) return true;
      if (m1 != 0 && visit(moved[k1], next[k1], m1)) return true;
      visit_taken(taken, taken_kept);
    }
    if (down_a != 0) {
      const float t[3] = {x.t[0] - x.node().center[0][x.lane], x.t[1] - x.node().center[1][x.lane],
                          x.t[2] - x.node().center[2][x.lane]};
      return descend_a(a_child, t, t_err_q, nb, down_a);
    }
    return false;
  }

  // The wanted children of B's node b (the lanes `allowed`), each hoisted in B's frame, against
  // the four children of A's node n in lanes: fewer kernel calls than A's boxes against b when
  // fewer lanes of b are wanted than n has boxes. Returns the lanes of b kept against each lane i
  // of n in bits 4 i to 4 i + 3. Not inlined: its frame stays off descend_a's, which recurses.
  [[gnu::noinline]] unsigned swapped_tests(const WideNode& n, const WideNode& b, const float (&t)[3], double t_err,
                                           unsigned allowed) {
    unsigned kept_by_a = 0;
    float s[3];
    double s_err;
    swap_point(f.r0, t, t_err, swap_fixed, s, s_err);
    const HoistedNode hb = hoist_node(fs, b, s, (s_err + swap_hoist) * (1.0 + 0x1p-50));
    // The wanted lanes in order, from a table rather than a loop over the mask's bits (whose
    // length the branch predictor cannot know).
    const int m = lanes_in(allowed);
    int lanes[kWideLanes];
    for (int k = 0; k < kWideLanes; ++k) lanes[k] = (kLaneLists[allowed & 0xFu] >> (2 * k)) & 3;
    kernel_calls += static_cast<unsigned>(m & ~1);
    for (int k = 0; k < m; k += 2) {
      const DescentBox y0 = fresh(hb, lanes[k], s, s_err);
      unsigned kept[2];
      if (k + 1 < m) {
        const DescentBox y1 = fresh(hb, lanes[k + 1], s, s_err);
        const unsigned both = wide_overlap2(y0.view(), n, y1.view(), n, avx2);
        kept[0] = both & 0xFu;
        kept[1] = both >> 4;
      } else {
        Waiting taken;
        unsigned taken_kept = 0;
        kept[0] = single(y0.view(), n, taken, taken_kept);
        kept[1] = 0;
        visit_taken(taken, taken_kept);
      }
      // Transposed without branches: kept[h]'s bit i to bit 4 i + lanes[k + h] (kept[1] is 0
      // past the last lane).
      kept_by_a |= static_cast<unsigned>(kSpread[kept[0]]) << lanes[k];
      kept_by_a |= static_cast<unsigned>(kSpread[kept[1]]) << lanes[k + 1];
    }
    return kept_by_a;
  }

  // Each box of A's node na against the lanes `allowed` of B's node nb. t, t_err: B's ref in na's
  // frame (DescentBox::t).
  bool descend_a(std::int32_t na, const float (&t)[3], double t_err, std::int32_t nb, unsigned allowed) {
    const WideNode& n = wa.nodes[static_cast<std::size_t>(na)];
    const WideNode& b = wb.nodes[static_cast<std::size_t>(nb)];
    const unsigned boxes_of_a = occupied(n);
    const int count = lanes_in(boxes_of_a), wanted = lanes_in(allowed);
    unsigned kept_by_a = 0;  // swapped: lane i of n kept the lanes of b in bits 4 i to 4 i + 3
    const bool swapped = swap && wanted < count;
    if (swapped) {
      box_tests += static_cast<std::uint64_t>(count) * static_cast<unsigned>(wanted);  // all tested at once
      kept_by_a = swapped_tests(n, b, t, t_err, allowed);
      if constexpr (Traced)
        for (unsigned w = boxes_of_a; w != 0; w &= w - 1) {
          const int lane = std::countr_zero(w);
          record(n, lane, nb, allowed, (kept_by_a >> (4 * lane)) & 0xFu);
        }
      if (kept_by_a == 0) return false;
    }
    HoistedNode hn = hoist_node(f, n, t, t_err);
    store4(hn.base, load4(hn.core) + splat4(base_add));  // descent_bounds' base, which moves keep
    DescentBox boxes[kWideLanes];
    unsigned box_masks[kWideLanes];
    for (int k = 0; k < kWideLanes; ++k) {  // all four slots, the boxes' lanes from the table
      const int lane = (kLaneLists[boxes_of_a] >> (2 * k)) & 3;
      boxes[k] = fresh(hn, lane, t, t_err);
      box_masks[k] = (kept_by_a >> (4 * lane)) & 0xFu;
    }
    int order[kWideLanes] = {0, 1, 2, 3};
    if constexpr (FirstHit) nearest_first(boxes, count, order);
    // As visit: two boxes per call in the visiting order, each pair tested just before its descents.
    for (int i = 0; i < count; i += 2) {
      const int k0 = order[i], k1 = i + 1 < count ? order[i + 1] : -1;
      Waiting taken;
      unsigned taken_kept = 0;
      if (!swapped) {  // counted as tested: first_hit may stop before the last boxes
        if (k1 >= 0) {
          kernel_calls += 2;
          box_tests += 2u * static_cast<unsigned>(wanted);
          const unsigned both = wide_overlap2(boxes[k0].view(), b, boxes[k1].view(), b, avx2);
          box_masks[k0] = both & allowed;
          box_masks[k1] = (both >> 4) & allowed;
        } else {
          box_tests += static_cast<unsigned>(wanted);
          box_masks[k0] = single(boxes[k0].view(), b, taken, taken_kept) & allowed;
        }
      }
      if constexpr (Traced) {
        if (!swapped) {  // the swapped tests were recorded when made
          record(n, boxes[k0].lane, nb, allowed, box_masks[k0]);
          if (k1 >= 0) record(n, boxes[k1].lane, nb, allowed, box_masks[k1]);
        }
      }
      if (box_masks[k0] != 0 && visit(boxes[k0], nb, box_masks[k0])) return true;
      if (k1 >= 0 && box_masks[k1] != 0 && visit(boxes[k1], nb, box_masks[k1])) return true;
      visit_taken(taken, taken_kept);
    }
    if constexpr (!FirstHit) flush_waiting(hn);
    return false;
  }
};

template <bool FirstHit, bool Traced = false>
void run(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb, const Mesh& mb,
         const Pose& rel, double margin, QueryResult& result, WideCounters* counters, bool swap,
         WideTraceSink* sink = nullptr) {
  // The roots first, as collide() does (its double test, box_test.hpp): a pair whose roots are
  // apart stops here at one test, where the wide roots would test A's root children against B's.
  // The scenes need it: their pairs come from world boxes that meet, and the roots' oriented boxes
  // cull many of those.
  if (!rel.rotation.allFinite() || !rel.translation.allFinite()) throw InputError("collide_wide: pose is not finite");
  ++result.stats.box_tests;
  MappedBox root_b;
  root_b.axes.noalias() = rel.rotation * tb.nodes[0].box.axes_d();
  root_b.center.noalias() = rel.rotation * tb.nodes[0].box.center_d() + rel.translation;
  const bool roots_overlap = box_overlap_grouped(ta.nodes[0].box, root_b, tb.nodes[0].box.half_extents,
                                                 box_allowance(ta, tb, rel) + margin);
  if constexpr (Traced)
    sink->tests.push_back({WideTraceSink::kRoot, WideTraceSink::kRoot, 0, 0,
                           roots_overlap ? PairOutcome::descended : PairOutcome::culled});
  if (!roots_overlap) return;
  const WideFrames frames = wide_frames(rel, wa.eta, wb.eta, margin);
  const WideFrame& fs = frames.swapped;
  TrianglePairBatch batch;
  MappedChunk mapped;
  Descent<FirstHit, Traced> d{ta,
                      wa,
                      ma,
                      tb,
                      wb,
                      mb,
                      rel,
                      frames.forward,
                      fs,
                      (fs.swap_rel * wb.ref_bound + fs.swap_abs) * (1.0 + 0x1p-50),
                      (fs.swap_rel * wb.reach_bound + fs.swap_abs) * (1.0 + 0x1p-50),
                      swap,
                      avx2_bounds_available(),
                      result,
                      batch,
                      mapped};
  // The wide roots are not tested: the children of A's root against those of B's.
  const WidePair root = wide_pair(d.f, wa.root_ref, wb.root_ref);
  const DescentBounds bounds = descent_bounds(wa, wb, root);
  d.t_err_q = bounds.t_err;
  d.margin = margin;
  d.base_add = up(2.0 * bounds.err);
  d.sink = sink;
  (void)d.descend_a(0, root.t, d.t_err_q, 0, occupied(wb.nodes[0]));
  assert(!d.waiting.full);  // the root's descend_a tested what waited
  if constexpr (!FirstHit) d.batch.flush(result);
  result.stats.box_tests += d.box_tests;
  result.stats.triangle_tests += d.triangle_tests;
  if (counters != nullptr) counters->kernel_calls += d.kernel_calls;
}

}  // namespace

namespace {

template <bool Traced>
QueryResult collide_on(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb,
                       const Mesh& mb, const Pose& rel, QueryMode mode, double margin, WideCounters* counters,
                       bool swap, WideTraceSink* sink) {
  QueryResult result;
  check_margin("collide_wide", margin);
  if (wa.nodes.empty() || wb.nodes.empty()) return result;
  check_tree_fits_mesh("collide_wide", ta, ma, "A");
  check_tree_fits_mesh("collide_wide", tb, mb, "B");
  if (mode == QueryMode::first_hit) {
    run<true, Traced>(ta, wa, ma, tb, wb, mb, rel, margin, result, counters, swap, sink);
  } else {
    run<false, Traced>(ta, wa, ma, tb, wb, mb, rel, margin, result, counters, swap, sink);
    sort_unique_pairs(result.pairs);
  }
  return result;
}

}  // namespace

QueryResult collide_wide_traced(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb,
                                const Mesh& mb, const Pose& rel, QueryMode mode, double margin, WideTraceSink& sink) {
  return collide_on<true>(ta, wa, ma, tb, wb, mb, rel, mode, margin, nullptr, true, &sink);
}

QueryResult collide_wide(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb,
                         const Mesh& mb, const Pose& rel, QueryMode mode, double margin, WideCounters* counters,
                         bool swap) {
  return collide_on<false>(ta, wa, ma, tb, wb, mb, rel, mode, margin, counters, swap, nullptr);
}

}  // namespace tightbvh::query_detail
