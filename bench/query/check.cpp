#include "check.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>

namespace tightbvh::bench {
namespace {

using TriDist = fcl::detail::TriangleDistance<double>;

struct PlacedPair {
  fcl::Vector3<double> s[3], t[3];
};

PlacedPair placed(const Input& in, const Pose& pose, Pair pair) {
  PlacedPair p;
  const auto ca = in.a.corners(pair.first);
  const auto cb = in.b.corners(pair.second);
  for (int i = 0; i < 3; ++i) {
    p.s[i] = ca[i];
    p.t[i] = pose.apply(cb[i]);
  }
  return p;
}

double distance(const PlacedPair& p, const Vec3& shift) {
  fcl::Vector3<double> t[3] = {p.t[0] + shift, p.t[1] + shift, p.t[2] + shift};
  fcl::Vector3<double> P, Q;
  return TriDist::triDistance(p.s, t, P, Q);
}

// True when a shift of B's triangle by `tol` (along the axes and both normals) separates a
// touching pair: the contact is within `tol` of grazing.
bool separable_within(const PlacedPair& p, double tol) {
  const Vec3 na = (p.s[1] - p.s[0]).cross(p.s[2] - p.s[0]).normalized();
  const Vec3 nb = (p.t[1] - p.t[0]).cross(p.t[2] - p.t[0]).normalized();
  for (const Vec3& d : {Vec3::UnitX().eval(), Vec3::UnitY().eval(), Vec3::UnitZ().eval(), na, nb}) {
    if (!d.allFinite()) continue;
    if (distance(p, tol * d) > 0 || distance(p, -tol * d) > 0) return true;
  }
  return false;
}

}  // namespace

double triangle_distance(const Input& in, const Pose& pose, Pair pair) {
  return distance(placed(in, pose, pair), Vec3::Zero());
}

Agreement compare_distances(const Answers& got, const std::vector<double>& reference, double scale) {
  Agreement a;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const double error = std::abs(got.distance[i] - reference[i]);
    a.max_distance_error = std::max(a.max_distance_error, error);
    if (!(error <= 1e-9 * reference[i] + 1e-12 * scale)) ++a.distances;
  }
  return a;
}

Agreement compare_exact_pairs(const Answers& got, const std::vector<std::vector<Pair>>& reference) {
  Agreement a;
  std::vector<Pair> differ;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    differ.clear();
    std::set_difference(reference[i].begin(), reference[i].end(), got.pairs[i].begin(), got.pairs[i].end(),
                        std::back_inserter(differ));
    const long missing = long(differ.size());
    differ.clear();
    std::set_difference(got.pairs[i].begin(), got.pairs[i].end(), reference[i].begin(), reference[i].end(),
                        std::back_inserter(differ));
    const long extra = long(differ.size());
    a.missing += missing, a.extra += extra;
    if (missing + extra > 0) ++a.pair_sets;
    if (bool(got.hit[i]) != !reference[i].empty()) ++a.yes_no;
  }
  return a;
}

Agreement compare_hits(const Answers& got, const std::vector<std::uint8_t>& reference) {
  Agreement a;
  for (std::size_t i = 0; i < reference.size(); ++i)
    if (got.hit[i] != reference[i]) ++a.yes_no;
  return a;
}

Agreement compare(const Input& in, Mode mode, const Answers& got, const std::vector<std::vector<Pair>>& reference,
                  const std::vector<Pose>& poses, double tolerance) {
  Agreement a;
  std::vector<Pair> missing, extra;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto& ref = reference[i];
    const bool ref_hit = !ref.empty();
    long pose_missing = 0, pose_extra = 0;
    if (mode == Mode::all_pairs) {
      const auto& mine = got.pairs[i];
      missing.clear();
      extra.clear();
      std::set_difference(ref.begin(), ref.end(), mine.begin(), mine.end(), std::back_inserter(missing));
      std::set_difference(mine.begin(), mine.end(), ref.begin(), ref.end(), std::back_inserter(extra));
      for (const Pair& p : missing) {
        if (separable_within(placed(in, poses[i], p), tolerance)) ++a.near_missing;
        else ++pose_missing;
      }
      for (const Pair& p : extra) {
        if (p.first >= in.a.triangles.size() || p.second >= in.b.triangles.size()) {  // not a triangle
          ++pose_extra;
          continue;
        }
        const double d = triangle_distance(in, poses[i], p);
        a.max_extra_distance = std::max(a.max_extra_distance, d);
        if (d <= tolerance) ++a.near_extra;
        else ++pose_extra;
      }
      a.missing += pose_missing;
      a.extra += pose_extra;
      if (pose_missing + pose_extra > 0) ++a.pair_sets;
    }
    if (bool(got.hit[i]) != ref_hit) {
      // A "no" against a reference whose every pair is a grazing contact is near-touching.
      const bool grazing = ref_hit && std::all_of(ref.begin(), ref.end(), [&](const Pair& p) {
                             return separable_within(placed(in, poses[i], p), tolerance);
                           });
      bool extra_near = false;
      if (!ref_hit && mode == Mode::all_pairs)
        extra_near = std::all_of(got.pairs[i].begin(), got.pairs[i].end(),
                                 [&](const Pair& p) {
                                   return p.first < in.a.triangles.size() && p.second < in.b.triangles.size() &&
                                          triangle_distance(in, poses[i], p) <= tolerance;
                                 });
      if (grazing || extra_near) ++a.yes_no_near;
      else ++a.yes_no;
    }
  }
  return a;
}

}  // namespace tightbvh::bench
