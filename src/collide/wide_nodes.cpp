// The wide nodes' construction: widening each box outward so that the float box contains the box
// it stands for, and the query frame's bounds. See wide_nodes.hpp.
#include "wide_nodes.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "tightbvh/error.hpp"

namespace tightbvh::query_detail {
namespace {

// The smallest float >= x (x finite, >= 0, within float's range). The next float up is the next
// bit pattern for a float >= 0 (no library call: the query frames round up per query).
float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) + 1u);
  return f;
}

// Gram deviation of float axes (columns of `af`): E = af^T af - I computed in double. Each product
// of two floats is exact in double; the two additions and the subtraction of delta_ik round by at
// most 3 2^-53 (|sum| + 1) < 1e-15, added to every |E_ik|.
struct Gram {
  double eta = 0.0;                 // max |E_ik|
  double norm = 0.0;                // max_i sum_k |E_ik| (>= |E|_2, E symmetric)
  double col[3] = {0.0, 0.0, 0.0};  // |E e_k|_2
};

Gram gram(const Eigen::Matrix3f& af) {
  Gram g;
  double e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      double s = 0.0;
      for (int l = 0; l < 3; ++l) s += static_cast<double>(af(l, i)) * static_cast<double>(af(l, k));
      e[i][k] = std::abs(s - (i == k ? 1.0 : 0.0)) + 1e-15;
      g.eta = std::max(g.eta, e[i][k]);
    }
  for (int i = 0; i < 3; ++i) {
    g.norm = std::max(g.norm, e[i][0] + e[i][1] + e[i][2]);
    g.col[i] = std::sqrt(e[0][i] * e[0][i] + e[1][i] * e[1][i] + e[2][i] * e[2][i]) * (1.0 + 0x1p-50);
  }
  return g;
}

// The widening. The box to contain is the parallelepiped { c + sum_k s_k g_k : |s_k| <= e_k } of
// generators g_k; the stored one is { ref + o + sum_k t_k a_k : |t_k| <= e'_k } with float axes
// a_k = g_k - Delta_k and float offset o = c - ref - Delta_c. A point x = c + sum s_k g_k is
//   x = ref + o + sum_k s_k a_k + r,   r = Delta_c + sum_k s_k Delta_k,
// and r = A v with v = A^-1 r, |v_i| <= |A^-1|_2 |r|_2 <= (|Delta_c|_2 + sum_k e_k |Delta_k|_2) /
// sqrt(1 - |E|) = delta, since sigma_min(A)^2 = lambda_min(A^T A) >= 1 - |E|_2 (E = A^T A - I). So
// t = s + v, and e'_i = e_i + delta contains x. Every double operation here rounds by at most
// 2^-53 relative; the (1 + 2^-48) factors cover them, and the half extents are rounded up to float.
WideBox widen(const Vec3& c, const Vec3& ref, const Eigen::Matrix3f& af, const Vec3& e, const double (&delta_k)[3],
              const Gram& g, double& eta) {
  if (!c.allFinite() || !ref.allFinite() || !e.allFinite() || !af.allFinite())
    throw InputError("wide nodes: a box or reference point is not finite");
  if (g.norm > 1e-3)
    throw InputError("wide nodes: box axes are far from orthonormal (|A^T A - I| = " + std::to_string(g.norm) + ")");
  WideBox out;
  double dc2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double off = c[k] - ref[k];
    out.center[k] = static_cast<float>(off);
    // off - float(off) is exact; c - ref itself rounded by at most 2^-53 |off|.
    const double dc = std::abs(off - static_cast<double>(out.center[k])) + 0x1p-53 * std::abs(off);
    dc2 += dc * dc;
  }
  double delta = std::sqrt(dc2) * (1.0 + 0x1p-50);
  for (int k = 0; k < 3; ++k) delta += e[k] * delta_k[k];
  delta = delta / std::sqrt(1.0 - g.norm) * (1.0 + 0x1p-48);
  for (int i = 0; i < 3; ++i) {
    if (e[i] < 0.0) throw InputError("wide nodes: a box has a negative half extent");
    out.half[i] = round_up((e[i] + delta) * (1.0 + 0x1p-50));
    for (int k = 0; k < 3; ++k) out.axes[3 * i + k] = af(k, i);
  }
  eta = std::max(eta, g.eta);
  return out;
}

}  // namespace

WideBox widen_box(const Obb& box, const Vec3& ref, double& eta) {
  const Eigen::Matrix3f af = box.axes.cast<float>();
  double delta_k[3];
  for (int k = 0; k < 3; ++k)  // g_k - a_k is exact in double (a_k is g_k rounded to float)
    delta_k[k] = (box.axes.col(k) - af.col(k).cast<double>()).norm() * (1.0 + 0x1p-50);
  return widen(box.center, ref, af, box.half_extents, delta_k, gram(af), eta);
}

// The slab box { x : |a_i . (x - c)| <= e_i } is the parallelepiped of generators g_k = A^-T e_k
// (columns of A^-T): Delta = A^-T - A = A^-T (I - A^T A) = -A^-T E, so |Delta_k|_2 <= |E e_k|_2 /
// sqrt(1 - |E|).
WideBox widen_box(const CompactBox& box, const Vec3& ref, double& eta) {
  const Gram g = gram(box.axes);
  double delta_k[3];
  for (int k = 0; k < 3; ++k) delta_k[k] = g.col[k] / std::sqrt(1.0 - std::min(g.norm, 0.5)) * (1.0 + 0x1p-50);
  return widen(box.center_d(), ref, box.axes, box.half_extents_d(), delta_k, g, eta);
}

namespace {

void set_lane(WideNode& n, int lane, const WideBox& b) {
  for (int r = 0; r < 9; ++r) n.axes[r][lane] = b.axes[r];
  for (int k = 0; k < 3; ++k) {
    n.center[k][lane] = b.center[k];
    n.half[k][lane] = b.half[k];
  }
}

WideNode empty_node() {
  WideNode n{};
  for (int lane = 0; lane < kWideLanes; ++lane) {
    for (int r = 0; r < 9; ++r) n.axes[r][lane] = (r % 4 == 0) ? 1.0f : 0.0f;  // identity
    for (int k = 0; k < 3; ++k) {
      n.center[k][lane] = 0.0f;
      n.half[k][lane] = kEmptyHalf;
    }
    n.child[lane] = 0;
  }
  return n;
}

// A bound on |s|_inf for the points s of box `lane` of n (ref `ref`), as swap_error takes it.
double reach(const WideNode& n, int lane, const Vec3& ref) {
  double r = 0.0;
  for (int k = 0; k < 3; ++k) r = std::max(r, std::abs(ref[k] + static_cast<double>(n.center[k][lane])));
  const double e = static_cast<double>(n.half[0][lane]) + n.half[1][lane] + n.half[2][lane];
  return (r + 1.01 * e) * (1.0 + 0x1p-50);
}

// |c|_1 of lane `lane`'s stored offset, rounded up.
double offset_norm(const WideNode& n, int lane) {
  return (std::abs(static_cast<double>(n.center[0][lane])) + std::abs(static_cast<double>(n.center[1][lane])) +
          std::abs(static_cast<double>(n.center[2][lane]))) *
         (1.0 + 0x1p-50);
}

struct Builder {
  const Tree& tree;
  WideTree& out;
  std::vector<std::uint32_t>* sources;
  std::uint64_t max_count;  // the most triangles one leaf reference holds: 2^leaf_bits

  // A new node (all lanes empty) whose ref is `ref`; `depth` counts the nodes above it, `path`
  // sums |c|_1 of the offsets that lead to it. Returns its index.
  std::int32_t open(const Vec3& ref, int depth, double path) {
    out.ref_bound = std::max(out.ref_bound, std::abs(ref[0]) + std::abs(ref[1]) + std::abs(ref[2]));
    out.depth = std::max(out.depth, depth);
    out.path_bound = std::max(out.path_bound, path);
    out.spread = std::max(out.spread, (ref - out.root_ref).lpNorm<1>() * (1.0 + 0x1p-50));
    const auto index = static_cast<std::int32_t>(out.nodes.size());
    out.nodes.push_back(empty_node());
    if (sources) sources->insert(sources->end(), {0u, 0u, 0u, 0u});
    return index;
  }

  // Lane `lane` of node `index` (ref `ref`) gets the box of tree node `source`.
  void fill(std::int32_t index, int lane, const Vec3& ref, std::uint32_t source) {
    WideNode& n = out.nodes[static_cast<std::size_t>(index)];
    set_lane(n, lane, widen_box(tree.nodes[source].box, ref, out.eta));
    out.reach_bound = std::max(out.reach_bound, reach(n, lane, ref));
    out.offset_bound = std::max(out.offset_bound, offset_norm(n, lane));
    if (sources) (*sources)[4 * static_cast<std::size_t>(index) + lane] = source;
  }

  // The child reference of triangles [first, first + count) of leaf `source`, whose box is in lane
  // `lane` of node `index` (ref `ref`, `depth`, `path` as in open). More triangles than one
  // reference holds go to a node below that lane with the same box in up to four lanes, each
  // holding a part of them (the same triangle pairs, a few more box tests).
  std::int32_t leaf(std::int32_t index, int lane, const Vec3& ref, int depth, double path, std::uint32_t source,
                    std::uint32_t first, std::uint32_t count) {
    if (count <= max_count) return ~static_cast<std::int32_t>(first << out.leaf_bits | (count - 1u));
    const WideNode& n = out.nodes[static_cast<std::size_t>(index)];
    const Vec3 ref_c = child_ref(ref, n, lane);
    const double path_c = path + offset_norm(n, lane);
    const std::int32_t c = open(ref_c, depth + 1, path_c);
    const std::uint64_t parts = std::min<std::uint64_t>(4, (count + max_count - 1) / max_count);
    std::uint32_t done = 0;
    for (int p = 0; p < static_cast<int>(parts); ++p) {
      const auto part = static_cast<std::uint32_t>((static_cast<std::uint64_t>(count) * (p + 1)) / parts) - done;
      fill(c, p, ref_c, source);
      const std::int32_t r = leaf(c, p, ref_c, depth + 1, path_c, source, first + done, part);
      out.nodes[static_cast<std::size_t>(c)].child[p] = r;
      done += part;
    }
    return c;
  }

  // The wide node of binary internal node `bi` whose ref is `ref` (depth and path as in open):
  // starting from bi's two children, the internal child with the largest box is replaced by its
  // two children until there are four (or only leaves): a node is full wherever the tree is deep
  // enough, which halves the node count against taking two levels as they come. Returns its index.
  std::int32_t make(std::uint32_t bi, const Vec3& ref, int depth, double path) {
    const Node& n = tree.nodes[bi];
    std::uint32_t kids[4] = {n.first, n.first + 1, 0, 0};
    int count = 2;
    while (count < 4) {
      int widest = -1;
      double widest_volume = -1.0;
      for (int k = 0; k < count; ++k) {
        const Node& c = tree.nodes[kids[k]];
        if (!c.is_leaf() && c.box.volume() > widest_volume) {
          widest = k;
          widest_volume = c.box.volume();
        }
      }
      if (widest < 0) break;
      const std::uint32_t first = tree.nodes[kids[widest]].first;
      kids[widest] = first;
      kids[count++] = first + 1;
    }
    const std::int32_t index = open(ref, depth, path);
    for (int lane = 0; lane < count; ++lane) fill(index, lane, ref, kids[lane]);
    for (int lane = 0; lane < count; ++lane) {
      const Node& g = tree.nodes[kids[lane]];
      const std::int32_t c =
          g.is_leaf() ? leaf(index, lane, ref, depth, path, kids[lane], g.first, g.count)
                      : make(kids[lane], child_ref(ref, out.nodes[static_cast<std::size_t>(index)], lane), depth + 1,
                             path + offset_norm(out.nodes[static_cast<std::size_t>(index)], lane));
      out.nodes[static_cast<std::size_t>(index)].child[lane] = c;
    }
    return index;
  }
};

// The fewest bits that hold v (0 for 0).
int bits_for(std::uint64_t v) { return static_cast<int>(std::bit_width(v)); }

}  // namespace

WideTree build_wide(const Tree& tree, std::vector<std::uint32_t>* sources, int max_leaf_bits) {
  WideTree out;
  if (tree.nodes.empty()) return out;
  if (sources) sources->clear();
  // Leaf references pack first << leaf_bits | (count - 1) into 31 bits.
  const std::size_t triangles = tree.triangle_order.size();
  const int first_bits = triangles == 0 ? 0 : bits_for(triangles - 1);
  if (first_bits > 31) throw InputError("wide nodes: more than 2^31 triangles");
  std::uint32_t largest = 1;
  for (const Node& n : tree.nodes)
    if (n.is_leaf()) largest = std::max(largest, n.count);
  out.leaf_bits = std::min({bits_for(largest - 1u), 31 - first_bits, std::clamp(max_leaf_bits, 0, 31)});
  Builder builder{tree, out, sources, std::uint64_t{1} << out.leaf_bits};
  const Node& root = tree.nodes[0];
  out.root_ref = root.box.center_d();
  out.ref_bound = std::abs(out.root_ref[0]) + std::abs(out.root_ref[1]) + std::abs(out.root_ref[2]);
  if (root.is_leaf()) {
    builder.open(out.root_ref, 0, 0.0);
    builder.fill(0, 0, out.root_ref, 0);
    out.nodes[0].child[0] = builder.leaf(0, 0, out.root_ref, 0, 0.0, 0, root.first, root.count);
    return out;
  }
  out.nodes.reserve(tree.nodes.size() / 3 + 1);
  builder.make(0, out.root_ref, 0, 0.0);
  return out;
}

double wide_bytes_per_triangle(const WideTree& wide, std::size_t triangles) {
  return triangles == 0 ? 0.0
                        : static_cast<double>(wide.nodes.size() * sizeof(WideNode)) / static_cast<double>(triangles);
}

namespace {

// max |M^T M - I| over the entries, in double, plus 1e-15 for the products' rounding (each entry:
// three products and two additions of terms <= 1 in size, and the subtraction of delta_ik).
double gram_deviation(const Mat3& m) {
  double d = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int k = i; k < 3; ++k)
      d = std::max(d, std::abs(m.col(i).dot(m.col(k)) - (i == k ? 1.0 : 0.0)));
  return d + 1e-15;
}

// The frame of the pose x -> r x + t, whose |r^T r - I| is within e0_max (gram_deviation(r)).
WideFrame make_frame(const Mat3& r, const Vec3& t, double e0_max, double eta_a, double eta_b, float margin) {
  WideFrame f;
  f.r0_d = r;
  f.t0_d = t;
  for (int l = 0; l < 3; ++l)
    for (int k = 0; k < 3; ++k) f.r0[3 * l + k] = static_cast<float>(r(l, k));
  // B's axes mapped by R0 have Gram B^T (I + E0) B (E0 = R0^T R0 - I): within eta_b + |E0|_2 (1 +
  // 3 eta_b) <= eta_b + 3.1 max |E0_ik| of I.
  const double eta = std::max(eta_a, eta_b + 3.1 * e0_max);
  if (eta > 1e-4) throw InputError("wide nodes: pose rotation or box axes far from orthonormal");
  f.kappa = round_up((8.0 * eta + 24.0 * 0x1p-24) * (1.0 + 1e-6));
  f.margin = margin;
  return f;
}

void check_frame_input(const Pose& rel, double margin) {
  if (!rel.rotation.allFinite() || !rel.translation.allFinite()) throw InputError("wide nodes: pose is not finite");
  if (!(margin >= 0.0) || !std::isfinite(margin)) throw InputError("wide nodes: margin must be finite and >= 0");
}

// The swapped frame from the forward pose's |R0^T R0 - I| bound `e0_max` (wide_frame_swapped).
WideFrame make_swapped(const Pose& rel, double e0_max, double eta_a, double eta_b, float margin) {
  const Mat3 rt = rel.rotation.transpose();
  const Vec3 t0 = -(rt * rel.translation);
  WideFrame f = make_frame(rt, t0, gram_deviation(rt), eta_b, eta_a, margin);
  f.swap_rel = 3.01 * e0_max;
  f.swap_abs = 0x1p-50 * 1.01 * rel.translation.cwiseAbs().sum();
  return f;
}

}  // namespace

WideFrame wide_frame(const Pose& rel, double eta_a, double eta_b, double margin) {
  check_frame_input(rel, margin);
  return make_frame(rel.rotation, rel.translation, gram_deviation(rel.rotation), eta_a, eta_b, round_up(margin));
}

// The swapped kernel: a box b of B (hoisted) against the children of a node of A (lanes), in B's
// mesh frame. It is the kernel of wide_overlap with the frame P' = (R0^T, -R0^T t0): every step of
// the allowance's derivation (wide_nodes.hpp) names A for the hoisted side and B for the lanes, and
// holds with the roles exchanged, because it uses of the frame only that its float rotation is the
// rounding of a double matrix whose |M^T M - I| enters eta (wide_frame computes that for R0^T:
// |R0 R0^T - I|, and eta_a, eta_b exchanged), and of the boxes only their stored widening. What
// is left is that P' is not the exact inverse of x -> R0 x + t0:
//   - Boxes of A and B that share a point q (in A's frame) are, mapped by P', P'(A) and P'(R0 B +
//     t0) = (I + E0) B with E0 = R0^T R0 - I; the point p = P'(q) of (I + E0) B is (I + E0) s for
//     s in B, so s = p - E0 s, |E0 s|_inf <= 3 e0 |s|_inf (e0 = max |E0_ik|, rounded up). So B and
//     P'(A) shifted by -E0 s share s: the kernel must keep a pair whose true relative position
//     is off by |E0 s|_inf <= 3 e0 |s|_inf in each component, the same as an error of that size in
//     t (B's node ref in the hoisted box's node frame, which enters the allowance as t_err), with
//     |s|_inf <= |ref + c|_inf + 1.01 sum e_k (s in the hoisted box of B: center ref + c, axes of
//     components <= 1 + eta): swap_rel = 3.01 e0 (the 0.01 covers the bound's double rounding).
//   - wide_pair treats t0' = -R0^T t0 as exact; as computed in double it is within
//     gamma_3 sum |R0_jk t0_j| <= 2^-50 1.01 |t0|_1 of -R0^T t0: swap_abs.
// Both are far below the allowance's own terms for a double rotation (e0 ~ 1e-16).
WideFrame wide_frame_swapped(const Pose& rel, double eta_a, double eta_b, double margin) {
  check_frame_input(rel, margin);
  return make_swapped(rel, gram_deviation(rel.rotation), eta_a, eta_b, round_up(margin));
}

WideFrames wide_frames(const Pose& rel, double eta_a, double eta_b, double margin) {
  check_frame_input(rel, margin);
  const double e0_max = gram_deviation(rel.rotation);
  const float m = round_up(margin);
  return {make_frame(rel.rotation, rel.translation, e0_max, eta_a, eta_b, m), make_swapped(rel, e0_max, eta_a, eta_b, m)};
}

WidePair wide_pair(const WideFrame& f, const Vec3& ref_a, const Vec3& ref_b) {
  WidePair p;
  double err = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double t = f.r0_d(k, 0) * ref_b[0] + f.r0_d(k, 1) * ref_b[1] + f.r0_d(k, 2) * ref_b[2] + f.t0_d[k] - ref_a[k];
    // Five double operations: within gamma_5 < 2^-50 of the sum of the terms' magnitudes.
    const double mag = std::abs(f.r0_d(k, 0) * ref_b[0]) + std::abs(f.r0_d(k, 1) * ref_b[1]) +
                       std::abs(f.r0_d(k, 2) * ref_b[2]) + std::abs(f.t0_d[k]) + std::abs(ref_a[k]);
    p.t[k] = static_cast<float>(t);
    err = std::max(err, std::abs(t - static_cast<double>(p.t[k])) + 0x1p-50 * mag * (1.0 + 0x1p-50));
  }
  // Rounded up without a branch: float(x (1 + 2^-20)) >= x (1 + 2^-20)(1 - 2^-24) > x for x in
  // float's normal range, which the 1e-30 puts it in.
  p.t_err = static_cast<float>(err * (1.0 + 0x1p-20) + 1e-30);
  return p;
}

}  // namespace tightbvh::query_detail
