// How far apart are two posed meshes, and where: the distance, the closest triangles and points
// (world frame and each mesh's own), then the cheaper variants: an error bound and an upper bound.
// Every answer is checked against the brute-force reference (every triangle pair); exit code 1 if
// one is wrong. A is cut to its first 800 triangles so that the reference takes well under a second.
//   distance_closest_points [MESH_A MESH_B]   (defaults: the shipped elephant and knot)
#include <tightbvh/build.hpp>
#include <tightbvh/distance.hpp>
#include <tightbvh/mesh.hpp>

#include <cmath>
#include <cstdio>
#include <exception>

int main(int argc, char** argv) try {
  const char* path_a = argc > 2 ? argv[1] : TIGHTBVH_SOURCE_DIR "/meshes/elephant.off";
  const char* path_b = argc > 2 ? argv[2] : TIGHTBVH_SOURCE_DIR "/meshes/knot1.off";
  tightbvh::Mesh a = tightbvh::load_mesh(path_a);
  if (a.triangles.size() > 800) a.triangles.resize(800);  // unused vertices are allowed
  const tightbvh::Mesh b = tightbvh::load_mesh(path_b);
  const tightbvh::Tree tree_a = tightbvh::build(a, {}), tree_b = tightbvh::build(b, {});

  // Both meshes posed in the world: A lifted, B turned 30 degrees about z and moved along x.
  tightbvh::Pose pose_a, pose_b;
  pose_a.translation = tightbvh::Vec3(0.0, 0.0, 0.5);
  pose_b.rotation = Eigen::AngleAxisd(M_PI / 6, tightbvh::Vec3::UnitZ()).toRotationMatrix();
  pose_b.translation = tightbvh::Vec3(1.2, 0.0, 0.5);

  const tightbvh::DistanceResult d = tightbvh::distance(tree_a, a, pose_a, tree_b, b, pose_b);
  std::printf("distance %.9f between triangle %u of A and triangle %u of B\n", d.distance, d.pair.a, d.pair.b);
  std::printf("  closest points (world): A (%.4f, %.4f, %.4f)  B (%.4f, %.4f, %.4f)\n", d.point_a.x(), d.point_a.y(),
              d.point_a.z(), d.point_b.x(), d.point_b.y(), d.point_b.z());
  std::printf("  the same in each mesh's frame: A (%.4f, %.4f, %.4f)  B (%.4f, %.4f, %.4f)\n", d.point_a_local.x(),
              d.point_a_local.y(), d.point_a_local.z(), d.point_b_local.x(), d.point_b_local.y(), d.point_b_local.z());

  // Cheaper queries: stop once within 5% of the minimum, or once nothing is closer than a bound.
  const tightbvh::DistanceResult rough =
      tightbvh::distance(tree_a, a, pose_a, tree_b, b, pose_b, {.relative_error = 0.05});
  const tightbvh::DistanceResult far =
      tightbvh::distance(tree_a, a, pose_a, tree_b, b, pose_b, {.upper_bound = 0.5 * d.distance});
  std::printf("within 5%%: %.9f (%llu triangle pairs measured, exact: %llu); below %.4f: %s\n", rough.distance,
              static_cast<unsigned long long>(rough.stats.triangle_pairs),
              static_cast<unsigned long long>(d.stats.triangle_pairs), 0.5 * d.distance,
              far.beyond_upper_bound ? "nothing closer" : "closer");

  // The checks: the reference's distance, points that are the distance apart and map to the
  // local ones by the poses, the error bound kept, and the upper bound reported.
  const tightbvh::DistanceResult reference = tightbvh::distance_brute_force(a, pose_a, b, pose_b);
  const double tolerance = 1e-12 * (1.0 + d.distance);
  const bool ok = std::abs(d.distance - reference.distance) <= tolerance &&
                  std::abs((d.point_a - d.point_b).norm() - d.distance) <= tolerance &&
                  (pose_a.apply(d.point_a_local) - d.point_a).norm() <= tolerance &&
                  (pose_b.apply(d.point_b_local) - d.point_b).norm() <= tolerance &&
                  rough.distance >= reference.distance - tolerance &&
                  rough.distance <= 1.05 * reference.distance + tolerance &&
                  far.beyond_upper_bound && far.distance == 0.5 * d.distance;
  std::printf("brute force: %.9f over %llu triangle pairs: %s\n", reference.distance,
              static_cast<unsigned long long>(reference.stats.triangle_pairs), ok ? "agrees" : "DISAGREES");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "distance_closest_points: %s\n", e.what());
  return 1;
}
