#include "splitter.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace tightbvh {

namespace {
constexpr std::array<std::pair<SplitMethod, std::string_view>, 3> kNames{{
    {SplitMethod::rapid, "rapid"},
    {SplitMethod::median, "median"},
    {SplitMethod::binned, "binned"},
}};
}  // namespace

std::optional<SplitMethod> parse_split_method(std::string_view name) {
  for (const auto& [method, text] : kNames)
    if (text == name) return method;
  if (name == "sah") return SplitMethod::binned;
  return std::nullopt;
}

std::string_view to_string(SplitMethod method) {
  for (const auto& [m, text] : kNames)
    if (m == method) return text;
  return "unknown";
}

namespace detail {
namespace {

using Index = std::uint32_t;

// Box axes from the longest to the shortest (ties: lower index first).
[[nodiscard]] std::array<int, 3> axes_by_length(const Obb& box) {
  std::array<int, 3> axes{0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(),
                   [&](int a, int b) { return box.half_extents[a] > box.half_extents[b]; });
  return axes;
}

// Half the triangles on each side along `dir`, ties broken by triangle index so the order of
// equal keys (duplicated triangles) never matters.
std::size_t split_by_count(std::span<Index> range, const Vec3& dir, const std::vector<Vec3>& centroids,
                           SplitScratch& scratch) {
  auto& keys = scratch.keys;
  keys.clear();
  for (const Index t : range) keys.emplace_back(centroids[t].dot(dir), t);
  const std::size_t mid = range.size() / 2;
  std::nth_element(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(mid), keys.end());
  for (std::size_t i = 0; i < range.size(); ++i) range[i] = keys[i].second;
  return mid;
}

// RAPID (Gottschalk et al. 1996, Section 4): the plane orthogonal to the longest box axis
// through the mean of the projected centroids; then the other axes; then by count.
std::size_t split_rapid(std::span<Index> range, const Obb& box, const std::vector<Vec3>& centroids,
                        SplitScratch& scratch) {
  const auto axes = axes_by_length(box);
  for (const int a : axes) {
    const Vec3 dir = box.axes.col(a);
    double sum = 0.0;
    for (const Index t : range) sum += centroids[t].dot(dir);
    const double mean = sum / static_cast<double>(range.size());
    const auto mid = std::partition(range.begin(), range.end(),
                                    [&](Index t) { return centroids[t].dot(dir) < mean; });
    const auto left = static_cast<std::size_t>(mid - range.begin());
    if (left != 0 && left != range.size()) return left;
  }
  return split_by_count(range, box.axes.col(axes[0]), centroids, scratch);
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
std::size_t split_binned(std::span<Index> range, const Obb& box, const Mesh& mesh,
                         const std::vector<Vec3>& centroids, SplitScratch& scratch) {
  constexpr int kBins = 32;
  const std::size_t n = range.size();
  scratch.bounds.resize(n);
  scratch.centers.resize(n);
  Aabb center_bounds;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = mesh.corners(range[i]);
    Aabb b;
    for (const Vec3& p : c) b.extend(box.to_local(p));
    scratch.bounds[i] = b;
    scratch.centers[i] = box.to_local(centroids[range[i]]);
    center_bounds.extend(scratch.centers[i]);
  }
  const auto bin_of = [&](std::size_t i, int axis) {
    const double lo = center_bounds.min[axis];
    const double scale = kBins / (center_bounds.max[axis] - lo);
    return std::min(kBins - 1, static_cast<int>((scratch.centers[i][axis] - lo) * scale));
  };

  double best_cost = std::numeric_limits<double>::infinity();
  int best_axis = -1;
  int best_bin = 0;
  for (int axis = 0; axis < 3; ++axis) {
    // Also skips spreads so small that kBins / spread overflows.
    if (!std::isfinite(kBins / (center_bounds.max[axis] - center_bounds.min[axis]))) continue;
    std::array<Aabb, kBins> bins{};
    std::array<std::size_t, kBins> counts{};
    for (std::size_t i = 0; i < n; ++i) {
      const int b = bin_of(i, axis);
      ++counts[b];
      bins[b].extend(scratch.bounds[i].min);
      bins[b].extend(scratch.bounds[i].max);
    }
    // right_cost[b]: cost of bins (b, kBins) on the right.
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
  if (best_axis < 0) return split_by_count(range, box.axes.col(axes_by_length(box)[0]), centroids, scratch);

  // Stable two-way partition by bin.
  auto& out = scratch.reordered;
  out.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (bin_of(i, best_axis) <= best_bin) out.push_back(range[i]);
  const std::size_t mid = out.size();
  for (std::size_t i = 0; i < n; ++i)
    if (bin_of(i, best_axis) > best_bin) out.push_back(range[i]);
  std::copy(out.begin(), out.end(), range.begin());
  return mid;
}

}  // namespace

std::size_t split(SplitMethod method, std::span<Index> range, const Obb& box, const Mesh& mesh,
                  const std::vector<Vec3>& centroids, SplitScratch& scratch) {
  switch (method) {
    case SplitMethod::rapid:
      return split_rapid(range, box, centroids, scratch);
    case SplitMethod::median:
      return split_by_count(range, box.axes.col(axes_by_length(box)[0]), centroids, scratch);
    case SplitMethod::binned:
      return split_binned(range, box, mesh, centroids, scratch);
  }
  return split_by_count(range, box.axes.col(0), centroids, scratch);
}

}  // namespace detail
}  // namespace tightbvh
