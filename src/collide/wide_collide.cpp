// collide's descent over two wide trees: a hoisted box of A descends B with B's reference point
// moved in float. See wide_collide.hpp.
#include "wide_collide.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "box_bounds4.hpp"
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

// Box `lane` of A's node `n` (ref ref_a) against B's node at ref_b, hoisted from the double refs.
DescentBox fresh(const WideFrame& f, const WideNode& n, int lane, const Vec3& ref_a, const float (&t)[3], double t_err) {
  const WideBox a = lane_box(n, lane);
  // In the swapped frame, its pose's error (wide_frame_swapped) counts as error of t.
  const double t_err_all = (t_err + swap_error(f, ref_a, a)) * (1.0 + 0x1p-50);
  const WidePair p{{t[0], t[1], t[2]}, up(t_err_all)};
  DescentBox x;
  x.h = hoist(f, p, a);
  // hoist's tn is within 4.8 u |d|_1 + 1.75 t_err of exact (d = t - ca as hoist rounds it: the
  // allowance section of wide_nodes.hpp), and its base adds 10 u |d|_1 + 4 t_err, over 1.8 times that.
  double d1 = 0.0;
  for (int k = 0; k < 3; ++k) d1 += std::abs(static_cast<double>(p.t[k] - a.center[k]));
  x.err = (4.8 * kU * d1 + 1.75 * static_cast<double>(p.t_err)) * (1.0 + 0x1p-50);
  x.core = f.kappa * (a.half[0] + a.half[1] + a.half[2] + f.margin) + f.margin;
  x.volume = a.half[0] * a.half[1] * a.half[2];
  x.node = &n;
  x.lane = lane;
  x.ref_a = ref_a;
  for (int k = 0; k < 3; ++k) x.t[k] = t[k];
  x.t_err = t_err_all;
  return x;
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
//     <= 1.01 2^-53 |ref_c|_1;
// so err' = err + 7.5 u |c|_1 + 1.01 u |tn'|_inf + 1.1 2^-53 |ref_c|_1 (computed in double, the
// (1 + 2^-50) factor covering its rounding). The kernel needs its tn within err of exact with
// base >= the rest of its allowance + 1.8 err (the allowance section: tn's error reaches each
// axis' offset through weights summing to <= 1.8), so base' = core + up(2 err'); the float sum
// can round it down by u relative, which the 2 against 1.8 covers.
void move_b(DescentBox& x, const WideNode& n, int lane, const Vec3& ref_c, const float (&f_r0)[9]) {
  const float c[3] = {n.center[0][lane], n.center[1][lane], n.center[2][lane]};
  float tinf = 0.0f;
  for (int i = 0; i < 3; ++i) {
    x.h.tn[i] = x.h.tn[i] + (x.h.m[3 * i] * c[0] + x.h.m[3 * i + 1] * c[1] + x.h.m[3 * i + 2] * c[2]);
    tinf = std::max(tinf, std::abs(x.h.tn[i]));
  }
  const double c1 = std::abs(static_cast<double>(c[0])) + std::abs(static_cast<double>(c[1])) +
                    std::abs(static_cast<double>(c[2]));
  const double r1 = std::abs(ref_c[0]) + std::abs(ref_c[1]) + std::abs(ref_c[2]);
  x.err = (x.err + 7.5 * kU * c1 + 1.01 * kU * static_cast<double>(tinf) + 1.1 * 0x1p-53 * r1) * (1.0 + 0x1p-50);
  x.h.base = x.core + up(2.0 * x.err);
  // B's ref in the frame of A's node, for the boxes of A's side (fresh): t' = fl(t + fl(R0f c)),
  // exact t + R0 c + R0 (ref_c - ref_b - c). With R0f = fl(R0) (entries within u of R0's,
  // |R0_ij| <= 1.0001): |(R0f - R0) c| <= 1.0001 u |c|_1, the dot product gamma_3 1.0001 |c|_1,
  // the addition 1.0001 u |t'|_inf, the refs' rounding 1.01 2^-53 |ref_c|_1 (as above).
  float t_inf = 0.0f;
  for (int k = 0; k < 3; ++k) {
    x.t[k] = x.t[k] + (f_r0[3 * k] * c[0] + f_r0[3 * k + 1] * c[1] + f_r0[3 * k + 2] * c[2]);
    t_inf = std::max(t_inf, std::abs(x.t[k]));
  }
  x.t_err = (x.t_err + 4.5 * kU * c1 + 1.01 * kU * static_cast<double>(t_inf) + 1.1 * 0x1p-53 * r1) * (1.0 + 0x1p-50);
}

// B's ref in the frame of the child node of A's box x (ref ref_c = x.ref_a (+) c, c the box's
// float offset), from x.t: t' = fl(t - c), exact t - c - (ref_c - ref_a - c): the subtraction
// rounds by 1.0001 u |t'|_inf, the refs' double additions by 2^-53 |ref_c|_1.
void move_a(const DescentBox& x, const Vec3& ref_c, float (&t)[3], double& t_err) {
  float t_inf = 0.0f;
  for (int k = 0; k < 3; ++k) {
    t[k] = x.t[k] - x.node->center[k][x.lane];
    t_inf = std::max(t_inf, std::abs(t[k]));
  }
  const double r1 = std::abs(ref_c[0]) + std::abs(ref_c[1]) + std::abs(ref_c[2]);
  t_err = (x.t_err + 1.01 * kU * static_cast<double>(t_inf) + 1.1 * 0x1p-53 * r1) * (1.0 + 0x1p-50);
}

namespace {

// first_hit visits a step's boxes nearest first (as traverse.hpp orders a split's child pairs):
// `order` gets 0..count-1 sorted by |tn|_1, the distance from A's box center to B's node ref (a
// node's ref is its box's center) in A's box frame.
template <class Call>
void nearest_first(const Call* calls, int count, int (&order)[kWideLanes]) {
  float key[kWideLanes];
  for (int k = 0; k < count; ++k) {
    const WideHoisted& h = calls[k].box.h;
    key[k] = std::abs(h.tn[0]) + std::abs(h.tn[1]) + std::abs(h.tn[2]);
    int i = k;
    for (; i > 0 && key[order[i - 1]] > key[k]; --i) order[i] = order[i - 1];
    order[i] = k;
  }
}

unsigned occupied(const WideNode& n) {
  unsigned m = 0;
  for (int l = 0; l < kWideLanes; ++l) m |= static_cast<unsigned>(!is_empty_lane(n, l)) << l;
  return m;
}

template <bool FirstHit>
struct Descent {
  const Tree& ta;
  const WideTree& wa;
  const Mesh& ma;
  const Tree& tb;
  const WideTree& wb;
  const Mesh& mb;
  const Pose& rel;
  WideFrame f;   // A's boxes hoisted, B's nodes in the lanes
  WideFrame fs;  // the swapped frame: B's boxes hoisted, A's nodes in the lanes
  bool avx2;
  QueryResult& result;
  TrianglePairBatch batch;
  MappedChunk mapped;
  std::uint64_t box_tests = 0, triangle_tests = 0, kernel_calls = 0;

  // The triangle pairs of A's leaf (ca, na) and B's leaf (cb, nb) (child references and counts),
  // in collide()'s order: B's triangles mapped into A's frame a chunk at a time. True: stop.
  bool leaves(std::int32_t ca, std::uint32_t na, std::int32_t cb, std::uint32_t nb) {
    const auto fa = static_cast<std::uint32_t>(~ca), fb = static_cast<std::uint32_t>(~cb);
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
            if (avx2) {
              batch.add(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2], ids, result);
              continue;
            }
          }
          if (tri_tri_overlap(p0, p1, p2, mapped[j][0], mapped[j][1], mapped[j][2])) {
            result.hit = true;
            result.pairs.push_back(ids);
            if constexpr (FirstHit) return true;
          }
        }
      }
    }
    return false;
  }

  // A kernel call queued by visit: box `box` (of the hoisted side's tree) against node `node` of
  // the other tree, whose ref is `ref`; `swap`: the call hoists the other side's box (a step of
  // the other orientation).
  struct Call {
    DescentBox box;
    std::int32_t node;
    Vec3 ref;
    bool swap;
  };

  const WideTree& tree(int side) const { return side == 0 ? wa : wb; }
  const WideFrame& frame(int side) const { return side == 0 ? f : fs; }

  // The kernel on calls[0..count): masks[k] the lanes of calls[k].node kept. Two calls at once.
  // side: the orientation of the visit that queued them (a swapped call's node is side's).
  void run_calls(const Call* calls, int count, unsigned* masks, int side) {
    for (int k = 0; k < count; k += 2) {
      const WideNode& n0 = tree(calls[k].swap ? side : 1 - side).nodes[static_cast<std::size_t>(calls[k].node)];
      box_tests += static_cast<unsigned>(std::popcount(occupied(n0)));
      ++kernel_calls;
      if (k + 1 < count) {
        const WideNode& n1 =
            tree(calls[k + 1].swap ? side : 1 - side).nodes[static_cast<std::size_t>(calls[k + 1].node)];
        box_tests += static_cast<unsigned>(std::popcount(occupied(n1)));
        ++kernel_calls;
        const unsigned both = wide_overlap2(calls[k].box.h, n0, calls[k + 1].box.h, n1, avx2);
        masks[k] = both & 0xFu;
        masks[k + 1] = both >> 4;
      } else {
        masks[k] = wide_overlap(calls[k].box.h, n0);
      }
    }
  }

  // Box x of side S's tree (hoisted in frame(S)) against node nl of the other tree (ref ref_l),
  // whose lanes `kept` the kernel kept. For each kept child of nl: both leaves, the triangle
  // pairs; the child internal and at least as large as x's box (volume), or x's box a leaf: x
  // descends it (move_b, its ref moved in float), a node-against-box call of four wanted lanes;
  // otherwise x's box opens: the child's box is hoisted in the other frame (fresh, its ref pair
  // from wide_pair in double) and tested against the four children of x's box: the swapped
  // kernel, four wanted lanes too. True: stop.
  template <int S>
  bool visit(const DescentBox& x, std::int32_t nl, const Vec3& ref_l, unsigned kept) {
    const WideNode& n = tree(1 - S).nodes[static_cast<std::size_t>(nl)];
    const std::int32_t h_child = x.node->child[x.lane];
    const std::uint32_t h_count = x.node->count[x.lane];
    unsigned moves = 0, swaps = 0;  // lanes of n that x descends, lanes whose box is hoisted
    for (unsigned m = kept; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      if (n.count[lane] > 0 && h_count > 0) {
        const bool stop = S == 0 ? leaves(h_child, h_count, n.child[lane], n.count[lane])
                                 : leaves(n.child[lane], n.count[lane], h_child, h_count);
        if (stop) return true;
        continue;
      }
      const float volume = n.half[0][lane] * n.half[1][lane] * n.half[2][lane];
      if (n.count[lane] == 0 && (h_count > 0 || volume >= x.volume))
        moves |= 1u << lane;
      else
        swaps |= 1u << lane;
    }
    // Both kinds of calls go through the kernel together, so that more of them pair up in eight
    // lanes (running x's own descent first for first_hit was not faster: query-core.md).
    return step<S>(x, n, ref_l, moves, swaps);
  }

  // visit's kernel calls: x against the child nodes of n's lanes `moves`, the boxes of n's lanes
  // `swaps` against x's child node; then the nodes kept, nearest first for first_hit.
  template <int S>
  bool step(const DescentBox& x, const WideNode& n, const Vec3& ref_l, unsigned moves, unsigned swaps) {
    Call calls[kWideLanes];
    int count = 0;
    for (unsigned m = moves; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      Call& c = calls[count++];
      c.node = n.child[lane];
      c.ref = child_ref(ref_l, n, lane);
      c.box = x;
      move_b(c.box, n, lane, c.ref, frame(S).r0);
      c.swap = false;
    }
    if (swaps != 0) {
      const Vec3 h_ref = child_ref(x.ref_a, *x.node, x.lane);
      for (unsigned m = swaps; m != 0; m &= m - 1) {
        const int lane = std::countr_zero(m);
        Call& c = calls[count++];
        const WidePair p = wide_pair(frame(1 - S), ref_l, h_ref);
        c.box = fresh(frame(1 - S), n, lane, ref_l, p.t, static_cast<double>(p.t_err));
        c.node = x.node->child[x.lane];
        c.ref = h_ref;
        c.swap = true;
      }
    }
    unsigned masks[kWideLanes];
    run_calls(calls, count, masks, S);
    int order[kWideLanes] = {0, 1, 2, 3};
    if constexpr (FirstHit) nearest_first(calls, count, order);
    for (int i = 0; i < count; ++i) {
      const int k = order[i];
      if (masks[k] == 0) continue;
      const bool stop = calls[k].swap ? visit<1 - S>(calls[k].box, calls[k].node, calls[k].ref, masks[k])
                                      : visit<S>(calls[k].box, calls[k].node, calls[k].ref, masks[k]);
      if (stop) return true;
    }
    return false;
  }

  // The roots: each box of A's root hoisted against the children of B's root.
  bool roots() {
    const WideNode& n = wa.nodes[0];
    const WidePair root = wide_pair(f, wa.root_ref, wb.root_ref);
    Call calls[kWideLanes];
    int count = 0;
    for (unsigned m = occupied(n); m != 0; m &= m - 1) {
      Call& c = calls[count++];
      c.box = fresh(f, n, std::countr_zero(m), wa.root_ref, root.t, static_cast<double>(root.t_err));
      c.node = 0;
      c.ref = wb.root_ref;
      c.swap = false;
    }
    unsigned masks[kWideLanes];
    run_calls(calls, count, masks, 0);
    int order[kWideLanes] = {0, 1, 2, 3};
    if constexpr (FirstHit) nearest_first(calls, count, order);
    for (int i = 0; i < count; ++i) {
      const int k = order[i];
      if (masks[k] != 0 && visit<0>(calls[k].box, 0, wb.root_ref, masks[k])) return true;
    }
    return false;
  }
};

template <bool FirstHit>
void run(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb, const Mesh& mb,
         const Pose& rel, QueryResult& result, WideCounters* counters) {
  Descent<FirstHit> d{ta,
                      wa,
                      ma,
                      tb,
                      wb,
                      mb,
                      rel,
                      wide_frame(rel, wa.eta, wb.eta, 0.0),
                      wide_frame_swapped(rel, wa.eta, wb.eta, 0.0),
                      avx2_bounds_available(),
                      result,
                      {},
                      {}};
  (void)d.roots();
  if constexpr (!FirstHit) d.batch.flush(result);
  result.stats.box_tests += d.box_tests;
  result.stats.triangle_tests += d.triangle_tests;
  if (counters != nullptr) counters->kernel_calls += d.kernel_calls;
}

}  // namespace

QueryResult collide_wide(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb,
                         const Mesh& mb, const Pose& rel, QueryMode mode, WideCounters* counters) {
  QueryResult result;
  if (wa.nodes.empty() || wb.nodes.empty()) return result;
  check_tree_fits_mesh("collide_wide", ta, ma, "A");
  check_tree_fits_mesh("collide_wide", tb, mb, "B");
  if (mode == QueryMode::first_hit) {
    run<true>(ta, wa, ma, tb, wb, mb, rel, result, counters);
  } else {
    run<false>(ta, wa, ma, tb, wb, mb, rel, result, counters);
    std::sort(result.pairs.begin(), result.pairs.end());
    result.pairs.erase(std::unique(result.pairs.begin(), result.pairs.end()), result.pairs.end());
  }
  return result;
}

}  // namespace tightbvh::query_detail
