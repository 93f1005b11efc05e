// The user guide's queries: poses, first_hit and all_pairs, a safety margin, distance with an
// upper bound, many poses with one workspace or in one batch, a coherent sequence with a
// QueryCache, contact geometry, point queries (checked against the brute force), the
// penetration of two solids (checked against the vertices' signed distances) and shapes against a
// mesh (checked against the brute force). Run by the tests
// (ctest guide_queries).
#include <tightbvh/build.hpp>
#include <tightbvh/collide.hpp>
#include <tightbvh/contact.hpp>
#include <tightbvh/distance.hpp>
#include <tightbvh/mesh.hpp>
#include <tightbvh/model.hpp>
#include <tightbvh/point_query.hpp>
#include <tightbvh/pose_text.hpp>
#include <tightbvh/query_cache.hpp>
#include <tightbvh/query_workspace.hpp>
#include <tightbvh/shape.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  const tightbvh::Mesh mesh_a = tightbvh::load_mesh(TIGHTBVH_SOURCE_DIR "/meshes/knot1.off");
  const tightbvh::Mesh mesh_b = tightbvh::load_mesh(TIGHTBVH_SOURCE_DIR "/meshes/elephant.off");
  const tightbvh::Tree tree_a = tightbvh::build(mesh_a);
  const tightbvh::Tree tree_b = tightbvh::build(mesh_b);

  // Poses place each mesh in the world: x -> rotation * x + translation. Only B relative to A
  // matters (relative_pose(pose_a, pose_b) = pose_a^-1 * pose_b).
  const tightbvh::Pose pose_a;  // the identity
  tightbvh::Pose pose_b;
  pose_b.rotation = Eigen::AngleAxisd(0.5, tightbvh::Vec3::UnitZ()).toRotationMatrix();
  pose_b.translation = tightbvh::Vec3(0.1, 0.0, 0.0);
  // A pose as the CLI's --pose text: the rotation row by row, then the translation.
  const tightbvh::Pose parsed = tightbvh::parse_pose("1 0 0  0 1 0  0 0 1  0.1 0 0");

  // Do they touch? first_hit stops at the first touching triangle pair.
  const tightbvh::QueryResult touch = tightbvh::collide(tree_a, mesh_a, pose_a, tree_b, mesh_b, pose_b);
  // Which triangles touch? all_pairs reports every pair, sorted and unique.
  const tightbvh::QueryResult all = tightbvh::collide(tree_a, mesh_a, pose_a, tree_b, mesh_b, parsed,
                                                      {.mode = tightbvh::QueryMode::all_pairs});
  // Which pairs are closer than 0.01? A safety margin.
  const tightbvh::QueryResult near = tightbvh::collide(tree_a, mesh_a, pose_a, tree_b, mesh_b, parsed,
                                                       {.mode = tightbvh::QueryMode::all_pairs, .margin = 0.01});
  std::printf("touch: %s, touching pairs: %zu, pairs within 0.01: %zu\n", touch.hit ? "yes" : "no",
              all.pairs.size(), near.pairs.size());

  // How far apart, and where? Within 5%, and not beyond 1.0 (then it stops early).
  pose_b.translation = tightbvh::Vec3(1.2, 0.0, 0.0);
  const tightbvh::DistanceResult gap = tightbvh::distance(tree_a, mesh_a, pose_a, tree_b, mesh_b, pose_b,
                                                          {.relative_error = 0.05, .upper_bound = 1.0});
  if (gap.beyond_upper_bound)
    std::printf("distance: at least %.3f\n", gap.distance);
  else
    std::printf("distance: %.4f between triangles %u and %u\n", gap.distance, gap.pair.a, gap.pair.b);

  // Many poses: one workspace per thread (no allocation per query), or one batch on all cores.
  std::vector<tightbvh::Pose> poses(64);
  for (std::size_t i = 0; i < poses.size(); ++i) poses[i].translation = tightbvh::Vec3(0.02 * i, 0.0, 0.0);
  tightbvh::QueryWorkspace workspace;
  std::size_t hits = 0;
  for (const tightbvh::Pose& p : poses)
    hits += tightbvh::collide(tree_a, mesh_a, pose_a, tree_b, mesh_b, p, {}, workspace).hit ? 1 : 0;
  const std::vector<tightbvh::QueryResult> batch =
      tightbvh::collide_batch(tree_a, mesh_a, pose_a, tree_b, mesh_b, poses, {}, /*threads=*/0);

  // A coherent sequence (consecutive poses close): the cache starts where the last query stopped.
  tightbvh::QueryCache cache;
  std::size_t cached_pairs = 0;
  for (const tightbvh::Pose& p : poses)
    cached_pairs += tightbvh::collide(tree_a, mesh_a, pose_a, tree_b, mesh_b, p,
                                      {.mode = tightbvh::QueryMode::all_pairs}, cache)
                        .pairs.size();
  std::printf("%zu of %zu poses hit (batch: %zu results), %zu pairs along the sequence\n", hits, poses.size(),
              batch.size(), cached_pairs);

  // Where do they cross? contacts (all_pairs, no margin): for each touching pair, where its two
  // triangles meet, in the world frame: a segment (a point when they only touch, a polygon when
  // coplanar), with both face normals. The segments make up the intersection curve.
  const tightbvh::QueryResult crossing = tightbvh::collide(tree_a, mesh_a, pose_a, tree_b, mesh_b, parsed,
                                                           {.mode = tightbvh::QueryMode::all_pairs, .contacts = true});
  std::size_t segments = 0;
  for (const tightbvh::Contact& c : crossing.contacts)
    segments += c.kind == tightbvh::ContactKind::segment ? 1 : 0;
  std::printf("contacts: %zu segments, intersection curve %.4f long\n", segments, crossing.curve_length);
  // The check: one contact per pair (the same pairs as above), each on both of its triangles.
  if (crossing.pairs != all.pairs || crossing.contacts.size() != all.pairs.size() || crossing.curve_length <= 0.0) {
    std::printf("contacts: not one per touching pair\n");
    return 1;
  }
  for (std::size_t i = 0; i < crossing.pairs.size(); ++i) {
    const auto ta = mesh_a.corners(crossing.pairs[i].a), tb = mesh_b.corners(crossing.pairs[i].b);
    const tightbvh::Contact& c = crossing.contacts[i];
    for (int k = 0; k < c.count; ++k) {
      const tightbvh::Vec3 in_b = parsed.inverse().apply(c.points[k]);  // pose_a is the identity
      if (tightbvh::closest_point_on_triangle(c.points[k], ta[0], ta[1], ta[2]).distance > 1e-9 ||
          tightbvh::closest_point_on_triangle(in_b, tb[0], tb[1], tb[2]).distance > 1e-9) {
        std::printf("contacts: pair %zu's contact is off its triangles\n", i);
        return 1;
      }
    }
  }

  // Point queries: a grid of points around the knot, each point's closest point on the surface,
  // its signed distance (negative inside) and whether it is inside. A Model keeps the mesh's
  // closedness, which the sign needs.
  const tightbvh::Model knot(mesh_a);
  std::vector<tightbvh::Vec3> points;
  for (int i = 0; i < 216; ++i) points.emplace_back(0.2 * (i % 6) - 0.5, 0.2 * (i / 6 % 6) - 0.5, 0.2 * (i / 36) - 0.5);
  const std::vector<tightbvh::ClosestPoint> closest = tightbvh::closest_points(knot, pose_a, points);
  const std::vector<tightbvh::ClosestPoint> sdf = tightbvh::signed_distance(knot, pose_a, points);
  const std::vector<tightbvh::Containment> where = tightbvh::contains(knot, pose_a, points);
  // closest[i].point lies on triangle closest[i].triangle at closest[i].barycentric, closest[i].distance away.

  // How deep do two solids overlap? Closed meshes only: minus the largest depth of a vertex of
  // either mesh inside the other solid, that vertex and its closest point on the other surface.
  const tightbvh::Model elephant(mesh_b);
  pose_b.translation = tightbvh::Vec3(0.1, 0.0, 0.0);
  const tightbvh::DistanceResult overlap =
      tightbvh::distance(knot, pose_a, elephant, pose_b, {.signed_distance = true});
  if (overlap.distance < 0.0)
    std::printf("penetration: %.4f, a vertex of %s\n", -overlap.distance,
                overlap.deepest == tightbvh::Inside::a_in_b ? "the knot (A) inside the elephant (B)"
                                                            : "the elephant (B) inside the knot (A)");
  else if (overlap.penetration_lower_bound_is_zero)
    std::printf("penetration: the surfaces touch or cross, no vertex inside: the bound is 0\n");

  // Two models along a sequence of close poses: the cache lets first_hit try the triangle pair
  // that touched last time (one triangle test) before it descends.
  tightbvh::QueryCache model_cache;
  std::size_t model_hits = 0;
  for (const tightbvh::Pose& p : poses)
    model_hits += tightbvh::collide(knot, pose_a, elephant, p, {}, model_cache).hit ? 1 : 0;
  if (model_hits != hits) {
    std::printf("models: %zu hits through the cache, %zu on the trees\n", model_hits, hits);
    return 1;
  }

  // The check: the brute force over every triangle, and the sign against contains.
  const std::vector<tightbvh::ClosestPoint> brute = tightbvh::closest_points_brute_force(mesh_a, pose_a, points);
  std::size_t inside = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const bool in = where[i] == tightbvh::Containment::inside;
    inside += in ? 1 : 0;
    if (closest[i].distance != brute[i].distance || closest[i].triangle != brute[i].triangle ||
        (sdf[i].distance < 0.0) != in || std::abs(sdf[i].distance) != closest[i].distance) {
      std::printf("point queries: point %zu disagrees with the brute force\n", i);
      return 1;
    }
  }
  // The penetration's check: no vertex of either mesh is deeper in the other solid than the
  // answer (the point queries' signed distance), and the deepest one is that deep.
  const auto deepest_of = [](const tightbvh::Model& from, const tightbvh::Pose& from_pose, const tightbvh::Model& into,
                             const tightbvh::Pose& into_pose) {
    std::vector<tightbvh::Vec3> world;
    for (const tightbvh::Vec3& v : from.mesh().vertices) world.push_back(from_pose.apply(v));
    double depth = 0.0;
    for (const tightbvh::ClosestPoint& c : tightbvh::signed_distance(into, into_pose, world))
      depth = std::max(depth, -c.distance);
    return depth;
  };
  const double want = std::max(deepest_of(knot, pose_a, elephant, pose_b), deepest_of(elephant, pose_b, knot, pose_a));
  if (!(overlap.distance < 0.0) || std::abs(-overlap.distance - want) > 1e-12 * (1.0 + want)) {
    std::printf("penetration: %.17g, but the vertices' signed distances give %.17g\n", -overlap.distance, want);
    return 1;
  }
  std::printf("point queries: %zu points, %zu inside, the brute force agrees\n", points.size(), inside);

  // Shapes against a mesh, kept exact (not tessellated), with FCL's conventions: a sphere of
  // radius 0.1, a box of full side lengths 0.2 x 0.1 x 0.3, a capsule of radius 0.05 whose axis
  // segment is 0.4 long along its local z; each centered at the origin of its pose.
  const tightbvh::Sphere ball(0.1);
  const tightbvh::Box crate(0.2, 0.1, 0.3);
  const tightbvh::Capsule link(0.05, 0.4);
  tightbvh::Pose shape_pose;
  shape_pose.translation = tightbvh::Vec3(0.3, 0.0, 0.0);
  const tightbvh::ShapeQueryResult ball_hits =
      tightbvh::collide(ball, shape_pose, knot, pose_a, {.mode = tightbvh::QueryMode::all_pairs});
  tightbvh::Pose above = shape_pose;  // the box above the knot
  above.translation.z() = 0.5;
  const tightbvh::ShapeDistanceResult crate_gap = tightbvh::distance(crate, above, knot, pose_a);
  const tightbvh::ShapeQueryResult link_near = tightbvh::collide(link, shape_pose, knot, pose_a, {.margin = 0.01});
  // ball_hits.triangles: the knot's triangles the sphere touches (sorted); crate_gap.distance,
  // .triangle, .point_shape and .point_mesh (world frame): 0 and a common point when touching.
  std::printf("shapes: the sphere touches %zu triangles, the box is %.4f away, the capsule %s within 0.01",
              ball_hits.triangles.size(), crate_gap.distance, link_near.hit ? "is" : "is not");
  // The check: the brute force over every triangle.
  const tightbvh::ShapeQueryResult ball_brute = tightbvh::collide_brute_force(
      ball, shape_pose, mesh_a, pose_a, {.mode = tightbvh::QueryMode::all_pairs});
  if (ball_hits.triangles != ball_brute.triangles ||
      crate_gap.distance != tightbvh::distance_brute_force(crate, above, mesh_a, pose_a).distance ||
      link_near.hit != tightbvh::collide_brute_force(link, shape_pose, mesh_a, pose_a, {.margin = 0.01}).hit) {
    std::printf("\nshapes: the brute force disagrees\n");
    return 1;
  }
  std::printf(", the brute force agrees\n");
  return 0;
}
