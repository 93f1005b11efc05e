#include "poses.hpp"

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "tightbvh/pose_text.hpp"

namespace tightbvh::bench {

std::string_view to_string(Scenario s) {
  switch (s) {
    case Scenario::overlap: return "overlap";
    case Scenario::near: return "near";
    case Scenario::separated: return "separated";
    case Scenario::gap: return "gap";
    case Scenario::trajectory: return "trajectory";
    case Scenario::inside: return "inside";
  }
  return "?";
}

std::optional<Scenario> parse_scenario(std::string_view name) {
  for (Scenario s : {Scenario::overlap, Scenario::near, Scenario::separated, Scenario::gap, Scenario::trajectory,
                     Scenario::inside})
    if (to_string(s) == name) return s;
  return std::nullopt;
}

Sphere bounding_sphere(const Mesh& mesh) {
  Sphere s;
  s.center = bounds_of(mesh.vertices).center();
  for (const Vec3& v : mesh.vertices) s.radius = std::max(s.radius, (v - s.center).norm());
  return s;
}

namespace {

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));  // uniform on SO(3) once normalised
  q.normalize();
  return q.toRotationMatrix();
}

Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 d;
  do d = Vec3(n(rng), n(rng), n(rng));
  while (d.norm() < 1e-9);
  return d.normalized();
}

// Pose putting B's (rotated) center at `where`.
Pose place(const Mat3& rotation, const Vec3& b_center, const Vec3& where) {
  return {rotation, where - rotation * b_center};
}

// Distance s along `dir` from A's center where B (with `rotation`) first touches A when coming
// from far away: march inwards until a collision, then bisect between the last free and the
// first touching sample. Returns 0 if B touches A at every sample.
double first_contact(const Sphere& sa, const Sphere& sb, const Mat3& rotation, const Vec3& dir,
                     const std::function<bool(const Pose&)>& collides) {
  const auto at = [&](double s) { return collides(place(rotation, sb.center, sa.center + s * dir)); };
  const double far = sa.radius + sb.radius;  // spheres apart beyond this
  constexpr int kSteps = 64;
  double free = far * 1.001, hit = -1;
  for (int i = 1; i <= kSteps; ++i) {
    const double s = far * (1.0 - double(i) / kSteps);
    if (at(s)) {
      hit = s;
      break;
    }
    free = s;
  }
  if (hit < 0) return 0;  // never touches along this line (e.g. through a hole): caller retries
  for (int i = 0; i < 60 && free - hit > 1e-12 * far; ++i) {
    const double mid = 0.5 * (free + hit);
    (at(mid) ? hit : free) = mid;
  }
  return free;  // the last known free distance: within bisection tolerance of contact
}

// From first contact at s along `dir`, the offset at which the meshes are `gap` apart: doubling,
// then bisection on the distance (which grows with the offset near contact, not always
// monotonically; any offset whose distance is within 0.1% of `gap` will do).
double offset_for_gap(const Sphere& sa, const Sphere& sb, const Mat3& rotation, const Vec3& dir, double s, double gap,
                      const std::function<double(const Pose&)>& distance) {
  const auto at = [&](double offset) { return distance(place(rotation, sb.center, sa.center + (s + offset) * dir)); };
  double lo = 0.0, hi = gap;
  for (int i = 0; i < 30 && at(hi) < gap; ++i) lo = hi, hi *= 2.0;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi), d = at(mid);
    if (std::abs(d - gap) <= 1e-3 * gap) return mid;
    (d < gap ? lo : hi) = mid;
  }
  return hi;
}

// One pass of the trajectory scenario (see poses.hpp): `count` consecutive poses, or none when the
// approach line misses A at a key frame (the caller draws another pass).
std::vector<Pose> trajectory_pass(const Sphere& sa, const Sphere& sb, int count, std::mt19937_64& rng,
                                  const std::function<bool(const Pose&)>& collides) {
  constexpr int kKeyEvery = 10;
  const Mat3 r0 = random_rotation(rng);
  const Vec3 spin = random_direction(rng), d0 = random_direction(rng);
  Vec3 turn = d0.cross(random_direction(rng));
  if (turn.norm() < 1e-6) turn = d0.unitOrthogonal();
  turn.normalize();
  const auto t_of = [&](int i) { return count > 1 ? double(i) / (count - 1) : 0.0; };
  const auto rotation = [&](double t) -> Mat3 { return Eigen::AngleAxisd(0.5 * t, spin).toRotationMatrix() * r0; };
  const auto direction = [&](double t) -> Vec3 { return Eigen::AngleAxisd(0.5 * t, turn) * d0; };
  // First contact at the key frames 0, kKeyEvery, ..., and at the last pose.
  std::vector<int> keys;
  for (int i = 0; i < count; i += kKeyEvery) keys.push_back(i);
  if (keys.back() != count - 1) keys.push_back(count - 1);
  std::vector<double> contact;
  for (const int k : keys) {
    const double s = first_contact(sa, sb, rotation(t_of(k)), direction(t_of(k)), collides);
    if (s <= 0) return {};
    contact.push_back(s);
  }
  std::vector<Pose> poses;
  for (int i = 0; i < count; ++i) {
    const std::size_t k = std::min<std::size_t>(i / kKeyEvery, keys.size() - 2);
    const double w = keys.size() > 1 ? double(i - keys[k]) / (keys[k + 1] - keys[k]) : 0.0;
    const double s = keys.size() > 1 ? (1 - w) * contact[k] + w * contact[k + 1] : contact[0];
    const double t = t_of(i);
    const double offset = 0.15 * std::cos(2.0 * M_PI * t) * sb.radius;
    poses.push_back(place(rotation(t), sb.center, sa.center + (s + offset) * direction(t)));
  }
  return poses;
}

}  // namespace

std::vector<Pose> generate_poses(const Mesh& a, const Mesh& b, Scenario scenario, int count, std::uint64_t seed,
                                 const std::function<bool(const Pose&)>& collides,
                                 const std::function<double(const Pose&)>& distance,
                                 const std::function<bool(const Pose&)>& contained) {
  if (scenario == Scenario::gap && !distance) throw std::logic_error("generate_poses: gap needs a distance");
  if (scenario == Scenario::inside && !contained) throw std::logic_error("generate_poses: inside needs `contained`");
  const double diagonal = std::max(bounds_of(a.vertices).diagonal(), bounds_of(b.vertices).diagonal());
  const Sphere sa = bounding_sphere(a), sb = bounding_sphere(b);
  // Each scenario gets its own stream, so `all` and a single scenario give the same poses.
  std::mt19937_64 rng(seed * 1000003u + static_cast<std::uint64_t>(scenario));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Pose> poses;
  poses.reserve(count);
  int attempts = 0;
  if (scenario == Scenario::trajectory) {
    while (int(poses.size()) < count) {
      const int n = std::min(kTrajectoryPass, count - int(poses.size()));
      std::vector<Pose> pass = trajectory_pass(sa, sb, n, rng, collides);
      if (pass.empty() && ++attempts < 100) continue;  // the line missed A: another pass
      if (pass.empty()) throw std::runtime_error("generate_poses: trajectory found no contact in 100 passes");
      poses.insert(poses.end(), pass.begin(), pass.end());
    }
    return poses;
  }
  while (int(poses.size()) < count) {
    const Mat3 rot = random_rotation(rng);
    const Vec3 dir = random_direction(rng);
    if (scenario == Scenario::inside) {
      const Aabb box = bounds_of(a.vertices);
      Vec3 where;
      for (int k = 0; k < 3; ++k)
        where[k] = box.min[k] - sb.radius + u(rng) * (box.max[k] - box.min[k] + 2.0 * sb.radius);
      const Pose pose = place(rot, sb.center, where);
      if (contained(pose)) poses.push_back(pose);
      else if (++attempts >= 1000 * count)
        throw InputError("inside: no pose with one mesh inside the other (without touching) in " +
                         std::to_string(attempts) + " tries; for meshes of similar size shrink B with --scale-b");
      continue;
    }
    if (scenario == Scenario::overlap) {
      const double r = 0.25 * std::min(sa.radius, sb.radius) * std::cbrt(u(rng));
      poses.push_back(place(rot, sb.center, sa.center + r * dir));
      continue;
    }
    const double s = first_contact(sa, sb, rot, dir, collides);
    if (s <= 0 && ++attempts < 100 * count) continue;  // no contact along this line: another one
    double offset;
    if (scenario == Scenario::near)
      offset = (2.0 * u(rng) - 1.0) * 0.01 * sb.radius;
    else if (scenario == Scenario::separated)
      offset = (0.05 + 0.20 * u(rng)) * sb.radius;
    else
      offset = offset_for_gap(sa, sb, rot, dir, s, (0.005 + 0.045 * u(rng)) * diagonal, distance);
    poses.push_back(place(rot, sb.center, sa.center + (s + offset) * dir));
  }
  return poses;
}

std::vector<Pose> read_poses(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open pose file");
  std::vector<Pose> poses;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;  // blank or comment only
    try {
      poses.push_back(parse_pose(line));
    } catch (const InputError& e) {
      throw InputError(path.string() + ":" + std::to_string(number) + ": " + e.what());
    }
  }
  if (poses.empty()) throw InputError(path.string() + ": no poses");
  return poses;
}

void write_poses(const std::filesystem::path& path, const std::vector<Pose>& poses, const std::string& header) {
  std::ofstream out(path);
  if (!out) throw InputError(path.string() + ": cannot write pose file");
  out << "# " << header << "\n# r00 r01 r02 r10 r11 r12 r20 r21 r22 tx ty tz (B's vertices in A's frame)\n";
  out.precision(17);
  for (const Pose& p : poses) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out << p.rotation(r, c) << ' ';
    out << p.translation.x() << ' ' << p.translation.y() << ' ' << p.translation.z() << '\n';
  }
  if (!out) throw InputError(path.string() + ": write failed");
}

}  // namespace tightbvh::bench
