#include "splitter.hpp"

#include "../name_table.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace tightbvh {

namespace {
constexpr detail::NameTable<SplitMethod, 3> kNames({{
    {SplitMethod::rapid, "rapid"},
    {SplitMethod::median, "median"},
    {SplitMethod::binned, "binned"},
}});
}  // namespace

std::optional<SplitMethod> parse_split_method(std::string_view name) {
  if (const auto method = kNames.parse(name)) return method;
  if (name == "sah") return SplitMethod::binned;
  return std::nullopt;
}

std::string_view to_string(SplitMethod method) {
  return kNames.name(method);
}

std::span<const SplitMethod> all_split_methods() { return kNames.values(); }
std::span<const std::string_view> split_method_names() { return kNames.names(); }

namespace detail {
namespace {

using Index = std::uint32_t;

// Three times the centroid: the splits only compare and average these, so the division is
// left out of the hot loops.
[[nodiscard]] inline Vec3 corner_sum(std::span<const Vec3> corners, std::size_t p) {
  return corners[3 * p] + corners[3 * p + 1] + corners[3 * p + 2];
}

void swap_positions(std::span<Index> order, std::span<Vec3> corners, std::span<VertexIds> ids, std::size_t a,
                    std::size_t b) {
  std::swap(order[a], order[b]);
  std::swap_ranges(corners.begin() + 3 * a, corners.begin() + 3 * a + 3, corners.begin() + 3 * b);
  if (!ids.empty()) std::swap(ids[a], ids[b]);
}

// Box axes from the longest to the shortest (ties: lower index first).
[[nodiscard]] std::array<int, 3> axes_by_length(const Obb& box) {
  const Vec3& e = box.half_extents;
  std::array<int, 3> axes{0, 1, 2};
  // Three-element stable sort (std::stable_sort would allocate a buffer).
  if (e[axes[1]] > e[axes[0]]) std::swap(axes[0], axes[1]);
  if (e[axes[2]] > e[axes[1]]) std::swap(axes[1], axes[2]);
  if (e[axes[1]] > e[axes[0]]) std::swap(axes[0], axes[1]);
  return axes;
}

// Applies a new order given as old positions: position i receives old position from[i].
template <class From>
void permute(std::span<Index> order, std::span<Vec3> corners, std::span<VertexIds> ids, std::size_t n, From from,
             SplitScratch& scratch) {
  scratch.order.assign(order.begin(), order.end());
  scratch.corners.assign(corners.begin(), corners.end());
  scratch.ids.assign(ids.begin(), ids.end());
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t p = from(i);
    order[i] = scratch.order[p];
    std::copy_n(scratch.corners.begin() + 3 * p, 3, corners.begin() + 3 * i);
    if (!ids.empty()) ids[i] = scratch.ids[p];
  }
}

// Half the triangles on each side along `dir` (the lower half goes left).
std::size_t split_by_count(std::span<Index> order, std::span<Vec3> corners, std::span<VertexIds> ids, const Vec3& dir, SplitScratch& scratch) {
  const std::size_t n = order.size();
  auto& keys = scratch.keys;
  keys.clear();
  for (std::size_t p = 0; p < n; ++p)
    keys.push_back({corner_sum(corners, p).dot(dir), order[p], static_cast<Index>(p)});
  const std::size_t mid = n / 2;
  std::nth_element(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(mid), keys.end(),
                   [](const SplitKey& a, const SplitKey& b) {
                     return a.key < b.key || (a.key == b.key && a.triangle < b.triangle);
                   });
  permute(order, corners, ids, n, [&](std::size_t i) { return keys[i].position; }, scratch);
  return mid;
}

// RAPID (Gottschalk, Lin & Manocha 1996, Section 4): the plane orthogonal to the longest box
// axis through the mean of the projected centroids; if a side is empty the next axis; then by
// count.
std::size_t split_rapid(std::span<Index> order, std::span<Vec3> corners, std::span<VertexIds> ids, const Obb& box, SplitScratch& scratch) {
  const std::size_t n = order.size();
  const auto axes = axes_by_length(box);
  auto& keys = scratch.projections;
  for (const int a : axes) {
    const Vec3 dir = box.axes.col(a);
    keys.resize(n);
    double sum = 0.0;
    for (std::size_t p = 0; p < n; ++p) sum += keys[p] = corner_sum(corners, p).dot(dir);
    const double mean = sum / static_cast<double>(n);
    // Hoare partition of the three arrays: left = centroid below the mean.
    std::size_t lo = 0, hi = n;
    while (true) {
      while (lo < hi && keys[lo] < mean) ++lo;
      while (lo < hi && !(keys[hi - 1] < mean)) --hi;
      if (lo + 1 >= hi) break;
      std::swap(keys[lo], keys[hi - 1]);
      swap_positions(order, corners, ids, lo, hi - 1);
      ++lo;
      --hi;
    }
    if (lo != 0 && lo != n) return lo;
  }
  return split_by_count(order, corners, ids, box.axes.col(axes[0]), scratch);
}

[[nodiscard]] double half_area(const Aabb& b) {
  if (b.empty()) return 0.0;
  const Vec3 e = b.extents();
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

// Binned surface-area split in the frame of the node's box: the children's boxes will be
// refitted, their bounds in the parent's frame are a cheap proxy of their size. Cost of a
// candidate: N_left * area(left) + N_right * area(right) (the expected number of overlap tests
// below the node when the other tree's nodes are small relative to these).
std::size_t split_binned(std::span<Index> order, std::span<Vec3> corners, std::span<VertexIds> ids, const Obb& box, SplitScratch& scratch) {
  constexpr int kBins = 32;
  const std::size_t n = order.size();
  scratch.bounds.resize(n);
  scratch.centers.resize(n);
  Aabb center_bounds;
  for (std::size_t p = 0; p < n; ++p) {
    Aabb b;
    for (int k = 0; k < 3; ++k) b.extend(box.to_local(corners[3 * p + k]));
    scratch.bounds[p] = b;
    scratch.centers[p] = box.to_local(corner_sum(corners, p) / 3.0);
    center_bounds.extend(scratch.centers[p]);
  }
  const auto bin_of = [&](std::size_t p, int axis) {
    const double lo = center_bounds.min[axis];
    const double scale = kBins / (center_bounds.max[axis] - lo);
    return std::min(kBins - 1, static_cast<int>((scratch.centers[p][axis] - lo) * scale));
  };

  double best_cost = std::numeric_limits<double>::infinity();
  int best_axis = -1;
  int best_bin = 0;
  for (int axis = 0; axis < 3; ++axis) {
    // Also skips spreads so small that kBins / spread overflows.
    if (!std::isfinite(kBins / (center_bounds.max[axis] - center_bounds.min[axis]))) continue;
    std::array<Aabb, kBins> bins{};
    std::array<std::size_t, kBins> counts{};
    for (std::size_t p = 0; p < n; ++p) {
      const int b = bin_of(p, axis);
      ++counts[b];
      bins[b].extend(scratch.bounds[p].min);
      bins[b].extend(scratch.bounds[p].max);
    }
    // right_cost[b]: cost of the bins after b.
    std::array<double, kBins> right_cost{};
    Aabb right;
    std::size_t right_count = 0;
    for (int b = kBins - 1; b > 0; --b) {
      right.extend(bins[b].min);
      right.extend(bins[b].max);
      right_count += counts[b];
      right_cost[b - 1] = static_cast<double>(right_count) * half_area(right);
    }
    Aabb left;
    std::size_t left_count = 0;
    for (int b = 0; b + 1 < kBins; ++b) {
      left.extend(bins[b].min);
      left.extend(bins[b].max);
      left_count += counts[b];
      if (left_count == 0 || left_count == n) continue;
      const double cost = static_cast<double>(left_count) * half_area(left) + right_cost[b];
      if (cost < best_cost) best_cost = cost, best_axis = axis, best_bin = b;
    }
  }
  if (best_axis < 0) return split_by_count(order, corners, ids, box.axes.col(axes_by_length(box)[0]), scratch);

  // Stable two-way partition by bin.
  auto& from = scratch.keys;
  from.clear();
  for (std::size_t p = 0; p < n; ++p)
    if (bin_of(p, best_axis) <= best_bin) from.push_back({0.0, 0, static_cast<Index>(p)});
  const std::size_t mid = from.size();
  for (std::size_t p = 0; p < n; ++p)
    if (bin_of(p, best_axis) > best_bin) from.push_back({0.0, 0, static_cast<Index>(p)});
  permute(order, corners, ids, n, [&](std::size_t i) { return from[i].position; }, scratch);
  return mid;
}

}  // namespace

std::size_t split(SplitMethod method, std::span<Index> order, std::span<Vec3> corners, std::span<VertexIds> ids,
                  const Obb& box, SplitScratch& scratch) {
  switch (method) {
    case SplitMethod::rapid:
      return split_rapid(order, corners, ids, box, scratch);
    case SplitMethod::median:
      return split_by_count(order, corners, ids, box.axes.col(axes_by_length(box)[0]), scratch);
    case SplitMethod::binned:
      return split_binned(order, corners, ids, box, scratch);
  }
  return split_by_count(order, corners, ids, box.axes.col(0), scratch);
}

}  // namespace detail
}  // namespace tightbvh
