#pragma once
// Pose scenarios and pose files. A pose is the rigid transform applied to B's vertices in A's
// frame (A stays at identity).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tightbvh/mesh.hpp"
#include "tightbvh/pose.hpp"

namespace tightbvh::bench {

enum class Scenario { overlap, near, separated, gap, trajectory, inside };
[[nodiscard]] std::string_view to_string(Scenario s);
[[nodiscard]] std::optional<Scenario> parse_scenario(std::string_view name);

// Bounding sphere (AABB center, max distance to a vertex) used to place the meshes.
struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 0;
};
[[nodiscard]] Sphere bounding_sphere(const Mesh& mesh);

// `collides(pose)` answers whether B at `pose` touches A (our exact query).
//   overlap:   B's center placed within 25% of the smaller radius of A's center (deep overlap)
//   near:      B at first contact along a random direction (march in from outside, then
//              bisection on `collides`), then jittered by +-1% of B's bounding radius
//   separated: first contact pushed out by 5..25% of B's bounding radius (close but apart)
//   gap:       first contact pushed out along the same line until the meshes are 0.5..5% of the
//              larger AABB diagonal apart (bisection on `distance`, to 0.1% of the gap)
//   trajectory: coherent sequences (QueryCache): passes of kTrajectoryPass consecutive poses along a
//              smooth path; B turns by 0.5 rad about a random axis while its approach direction
//              turns by 0.5 rad, and moves from 15% of its bounding radius outside first contact to
//              15% inside and back out (offset 0.15 cos(2 pi t) r_B from the first contact, which
//              is bisected every 10 poses and interpolated linearly in between)
inline constexpr int kTrajectoryPass = 100;
//   inside:    B's center anywhere in A's box grown by B's radius, kept when `contained` (one
//              mesh wholly inside the other, surfaces apart); InputError when none is found
//              (meshes of similar size: shrink B with tightbvh-bench --scale-b)
// Rotations are uniform random. Deterministic for a given seed.
[[nodiscard]] std::vector<Pose> generate_poses(const Mesh& a, const Mesh& b, Scenario scenario, int count,
                                               std::uint64_t seed,
                                               const std::function<bool(const Pose&)>& collides,
                                               const std::function<double(const Pose&)>& distance = {},
                                               const std::function<bool(const Pose&)>& contained = {});

// One pose per line: r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz; '#' starts a comment.
// Throws InputError naming the file and line on a wrong count, a non-number, NaN/Inf or a
// rotation that is not orthonormal with determinant +1 (tolerance 1e-6).
[[nodiscard]] std::vector<Pose> read_poses(const std::filesystem::path& path);
void write_poses(const std::filesystem::path& path, const std::vector<Pose>& poses, const std::string& header);

}  // namespace tightbvh::bench
