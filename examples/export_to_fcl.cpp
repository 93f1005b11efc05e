// Using tightbvh's trees inside FCL: to_fcl exports a tree (our topology, our boxes) as an
// fcl::BVHModel, which fcl::collide and fcl::distance then query like any FCL model. The answers
// are compared with tightbvh's own collide and distance; exit code 1 if they differ.
// Link tightbvh::tightbvh_fcl (built where FCL 0.7 is installed).
//   export_to_fcl [MESH_A MESH_B]   (defaults: the shipped elephant and knot)
#include <tightbvh/build.hpp>
#include <tightbvh/collide.hpp>
#include <tightbvh/distance.hpp>
#include <tightbvh/fcl/export.hpp>
#include <tightbvh/mesh.hpp>

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <vector>

int main(int argc, char** argv) try {
  const char* path_a = argc > 2 ? argv[1] : TIGHTBVH_SOURCE_DIR "/meshes/elephant.off";
  const char* path_b = argc > 2 ? argv[2] : TIGHTBVH_SOURCE_DIR "/meshes/knot1.off";
  const tightbvh::Mesh a = tightbvh::load_mesh(path_a);
  const tightbvh::Mesh b = tightbvh::load_mesh(path_b);
  const tightbvh::Tree tree_a = tightbvh::build(a, {}), tree_b = tightbvh::build(b, {});
  const auto fcl_a = tightbvh::to_fcl(tree_a, a), fcl_b = tightbvh::to_fcl(tree_b, b);  // OBB models

  // B touching A: every contact from FCL, the triangle indices are the meshes' own.
  tightbvh::Pose pose_b;
  pose_b.translation = tightbvh::Vec3(0.2, 0.0, 0.0);
  fcl::Transform3<double> tf_b = fcl::Transform3<double>::Identity();
  tf_b.translation() = pose_b.translation;
  fcl::CollisionRequest<double> request(std::numeric_limits<std::size_t>::max(), false);
  fcl::CollisionResult<double> contacts;
  fcl::collide(fcl_a.get(), fcl::Transform3<double>::Identity(), fcl_b.get(), tf_b, request, contacts);
  std::vector<tightbvh::TrianglePair> theirs;
  for (std::size_t i = 0; i < contacts.numContacts(); ++i)
    theirs.push_back({static_cast<std::uint32_t>(contacts.getContact(i).b1),
                      static_cast<std::uint32_t>(contacts.getContact(i).b2)});
  std::sort(theirs.begin(), theirs.end());
  const tightbvh::QueryResult ours = tightbvh::collide(tree_a, a, {}, tree_b, b, pose_b,
                                                       {.mode = tightbvh::QueryMode::all_pairs});
  std::printf("fcl::collide on the exported trees: %zu touching pairs (tightbvh::collide: %zu)\n", theirs.size(),
              ours.pairs.size());

  // B moved away: fcl::distance needs a distance volume, so export RSS boxes (or to_fcl_obbrss).
  pose_b.translation.x() = 1.5;
  tf_b.translation() = pose_b.translation;
  const auto rss_a = tightbvh::to_fcl_rss(tree_a, a), rss_b = tightbvh::to_fcl_rss(tree_b, b);
  fcl::DistanceResult<double> gap;
  fcl::distance(rss_a.get(), fcl::Transform3<double>::Identity(), rss_b.get(), tf_b, fcl::DistanceRequest<double>(),
                gap);
  const double our_gap = tightbvh::distance(tree_a, a, {}, tree_b, b, pose_b).distance;
  std::printf("fcl::distance on the exported RSS trees: %.9f (tightbvh::distance: %.9f)\n", gap.min_distance, our_gap);

  // Both libraries test the same triangle pairs with their own arithmetic: equal answers here.
  if (theirs != ours.pairs || std::abs(gap.min_distance - our_gap) > 1e-9 * our_gap) {
    std::fprintf(stderr, "export_to_fcl: FCL's answers differ from tightbvh's\n");
    return 1;
  }
  std::printf("FCL and tightbvh agree\n");
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "export_to_fcl: %s\n", e.what());
  return 1;
}
