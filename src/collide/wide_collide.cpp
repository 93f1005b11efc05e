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
  const WidePair p{{t[0], t[1], t[2]}, up(t_err)};
  const WideBox a = lane_box(n, lane);
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
  x.t_err = t_err;
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
void nearest_first(const DescentBox* boxes, int count, int (&order)[kWideLanes]) {
  float key[kWideLanes];
  for (int k = 0; k < count; ++k) {
    key[k] = std::abs(boxes[k].h.tn[0]) + std::abs(boxes[k].h.tn[1]) + std::abs(boxes[k].h.tn[2]);
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
  WideFrame f;
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

  // Box x of A against B's node nb (ref ref_b), whose lanes `kept` the kernel kept. True: stop.
  bool visit(const DescentBox& x, std::int32_t nb, const Vec3& ref_b, unsigned kept) {
    const WideNode& n = wb.nodes[static_cast<std::size_t>(nb)];
    const std::int32_t a_child = x.node->child[x.lane];
    const std::uint32_t a_count = x.node->count[x.lane];
    unsigned down_a = 0;  // lanes of n met by the children of x
    DescentBox moved[kWideLanes];
    std::int32_t next[kWideLanes];
    Vec3 next_ref[kWideLanes];
    int moves = 0;
    for (unsigned m = kept; m != 0; m &= m - 1) {
      const int lane = std::countr_zero(m);
      if (n.count[lane] > 0) {  // a leaf of B
        if (a_count > 0) {
          if (leaves(a_child, a_count, n.child[lane], n.count[lane])) return true;
        } else {
          down_a |= 1u << lane;
        }
        continue;
      }
      const float volume = n.half[0][lane] * n.half[1][lane] * n.half[2][lane];
      if (a_count > 0 || volume >= x.volume) {
        next[moves] = n.child[lane];
        next_ref[moves] = child_ref(ref_b, n, lane);
        moved[moves] = x;
        move_b(moved[moves], n, lane, next_ref[moves], f.r0);
        ++moves;
      } else {
        down_a |= 1u << lane;
      }
    }
    unsigned masks[kWideLanes];
    for (int k = 0; k < moves; k += 2) {
      const WideNode& b0 = wb.nodes[static_cast<std::size_t>(next[k])];
      box_tests += static_cast<unsigned>(std::popcount(occupied(b0)));
      kernel_calls += k + 1 < moves ? 2 : 1;
      if (k + 1 < moves) {
        const WideNode& b1 = wb.nodes[static_cast<std::size_t>(next[k + 1])];
        box_tests += static_cast<unsigned>(std::popcount(occupied(b1)));
        const unsigned both = wide_overlap2(moved[k].h, b0, moved[k + 1].h, b1, avx2);
        masks[k] = both & 0xFu;
        masks[k + 1] = both >> 4;
      } else {
        masks[k] = wide_overlap(moved[k].h, b0);
      }
    }
    int order[kWideLanes] = {0, 1, 2, 3};
    if constexpr (FirstHit) nearest_first(moved, moves, order);
    for (int i = 0; i < moves; ++i) {
      const int k = order[i];
      if (masks[k] != 0 && visit(moved[k], next[k], next_ref[k], masks[k])) return true;
    }
    if (down_a != 0) {
      const Vec3 ref_c = child_ref(x.ref_a, *x.node, x.lane);
      float t[3];
      double t_err;
      move_a(x, ref_c, t, t_err);
      return descend_a(a_child, ref_c, t, t_err, nb, ref_b, down_a);
    }
    return false;
  }

  // Each box of A's node na (ref ref_a) against the lanes `allowed` of B's node nb (ref ref_b).
  // t, t_err: B's ref in na's frame (DescentBox::t).
  bool descend_a(std::int32_t na, const Vec3& ref_a, const float (&t)[3], double t_err, std::int32_t nb,
                 const Vec3& ref_b, unsigned allowed) {
    const WideNode& n = wa.nodes[static_cast<std::size_t>(na)];
    const WideNode& b = wb.nodes[static_cast<std::size_t>(nb)];
    DescentBox boxes[kWideLanes];
    int count = 0;
    for (unsigned m = occupied(n); m != 0; m &= m - 1) boxes[count++] = fresh(f, n, std::countr_zero(m), ref_a, t, t_err);
    box_tests += static_cast<std::uint64_t>(count) * static_cast<unsigned>(std::popcount(allowed));
    unsigned masks[kWideLanes];
    for (int k = 0; k < count; k += 2) {
      kernel_calls += k + 1 < count ? 2 : 1;
      if (k + 1 < count) {
        const unsigned both = wide_overlap2(boxes[k].h, b, boxes[k + 1].h, b, avx2);
        masks[k] = both & allowed;
        masks[k + 1] = (both >> 4) & allowed;
      } else {
        masks[k] = wide_overlap(boxes[k].h, b) & allowed;
      }
    }
    int order[kWideLanes] = {0, 1, 2, 3};
    if constexpr (FirstHit) nearest_first(boxes, count, order);
    for (int i = 0; i < count; ++i) {
      const int k = order[i];
      if (masks[k] != 0 && visit(boxes[k], nb, ref_b, masks[k])) return true;
    }
    return false;
  }
};

template <bool FirstHit>
void run(const Tree& ta, const WideTree& wa, const Mesh& ma, const Tree& tb, const WideTree& wb, const Mesh& mb,
         const Pose& rel, QueryResult& result, WideCounters* counters) {
  Descent<FirstHit> d{ta, wa, ma, tb, wb, mb, rel, wide_frame(rel, wa.eta, wb.eta, 0.0), avx2_bounds_available(),
                      result, {}, {}};
  // The roots are not tested: the children of A's root against those of B's.
  const WidePair root = wide_pair(d.f, wa.root_ref, wb.root_ref);
  (void)d.descend_a(0, wa.root_ref, root.t, static_cast<double>(root.t_err), 0, wb.root_ref, occupied(wb.nodes[0]));
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
