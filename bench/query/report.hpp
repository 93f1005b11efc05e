#pragma once
// --report DIR: a self-contained HTML page (inline SVG, no scripts, no network).
#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "output.hpp"

namespace tightbvh::bench {

// One typical pose of a scenario, drawn in the report with its contacts.
struct PosePicture {
  std::string scenario;
  std::size_t index = 0, poses = 0;  // which pose of how many
  Pose pose;                         // B in A's frame
  std::vector<Pair> pairs;           // the reference's touching pairs at that pose
  std::string why;                   // how it was chosen
};

// The pose with the median number of touching pairs among the poses that touch (the first pose
// when none does). `pairs` holds each pose's reference pairs, or is empty when they were not
// computed (then the first pose, with pairs_of(its pose)).
template <class PairsOf>
[[nodiscard]] PosePicture typical_pose(const std::string& scenario, const std::vector<Pose>& poses,
                                       const std::vector<std::vector<Pair>>& pairs, PairsOf&& pairs_of) {
  PosePicture picture{scenario, 0, poses.size(), poses.empty() ? Pose{} : poses[0], {}, {}};
  std::vector<std::size_t> touching;
  for (std::size_t i = 0; i < pairs.size() && i < poses.size(); ++i)
    if (!pairs[i].empty()) touching.push_back(i);
  if (!touching.empty()) {
    std::stable_sort(touching.begin(), touching.end(),
                     [&](std::size_t x, std::size_t y) { return pairs[x].size() < pairs[y].size(); });
    picture.index = touching[touching.size() / 2];
    picture.pose = poses[picture.index];
    picture.pairs = pairs[picture.index];
    picture.why =
        "the median number of touching pairs among the " + std::to_string(touching.size()) + " touching poses";
  } else if (!poses.empty()) {
    picture.pairs = pairs.empty() ? pairs_of(poses[0]) : pairs[0];
    picture.why = pairs.empty() ? "the first pose" : "the first pose (no pose touches)";
  }
  return picture;
}

// Above this many triangles a mesh is drawn decimated (vertex clustering, apps/view/decimate.hpp)
// in the pose pictures; contacts are always drawn from the full meshes.
inline constexpr std::size_t kMaxPictureTriangles = 3'000;

// Writes dir/index.html and, per picture, dir/pose-SCENARIO.svg (the same picture on its own,
// what bench/query/check-report.sh renders and counts pixels of).
void write_report(const std::filesystem::path& dir, const RunInfo& info, const std::vector<Row>& rows,
                  const Input& input, const std::vector<PosePicture>& pictures);

}  // namespace tightbvh::bench
