// Google Benchmark of the shape queries (shape.hpp) against FCL 0.7, one thread each: a sphere, a
// box or a capsule against a mesh, poses per second of
// - ShapeCollide: tightbvh's collide() on a Model (first_hit) against fcl::collide of the
//   fcl::Sphere/Box/Capsule and an fcl::BVHModel<OBBRSS> of the same mesh (one contact, no
//   contact geometry);
// - ShapeDistance: tightbvh's distance() against fcl::distance (the default DistanceRequest: exact
//   bounds, rel_err = abs_err = 0, no nearest points).
// Each (shape, mesh, scenario) has a fixed set of kPoses shape poses (deterministic RNG, shape sizes
// 5-10% of the mesh's bounding-box diagonal): touching (the shape's center on the surface), near
// (apart by about 1% of the diagonal) and apart (about 20%), the distances measured exactly when the
// poses are drawn. The answers are checked in the same run against collide_brute_force and
// distance_brute_force (computed once, outside the timed loops): a wrong yes/no of either engine,
// or a tightbvh distance off by more than 1e-12 relative, makes the benchmark an error instead of
// a time. FCL's shape-triangle distance is approximate for the box and the capsule (libccd's GJK):
// its largest relative error over the poses is the counter fcl_max_rel_error, and an error above
// kFclTolerance is a benchmark error too. The counter triangles_per_pose: tightbvh's triangle tests
// (collide) or triangles measured (distance) per pose; nodes_per_pose: the nodes bounded (distance).
// - ShapeCollide/bullet: Bullet 3's btSphereShape, btBoxShape (margin 0, the same outer size) and
//   btCapsuleShapeZ against a btBvhTriangleMeshShape of the same mesh (its quantized BVH, Bullet's
//   choice for a static mesh), through btCollisionWorld::contactPairTest: touching when a reported
//   point has distance <= 0. Bullet has no early exit and its convex–triangle contacts come from
//   GJK/EPA, so its yes/no is counted against brute force (bullet_wrong_poses) rather than
//   required. Bullet has no shape–mesh distance query, so it has no ShapeDistance row.
// FCL and Bullet stay in this one translation unit.
#include <benchmark/benchmark.h>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#ifdef TIGHTBVH_SHAPE_BULLET
#include <btBulletCollisionCommon.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tightbvh/mesh.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/shape.hpp"

namespace {

using tightbvh::Pose;
using tightbvh::Vec3;
using FclMesh = fcl::BVHModel<fcl::OBBRSSd>;

constexpr std::size_t kPoses = 64;
// FCL's largest relative distance error accepted (the measured one is reported as a counter).
constexpr double kFclTolerance = 1e-2;

struct MeshEntry {
  const char* name;  // in the benchmark names
  const char* path;  // relative to the source tree
};
const MeshEntry kMeshes[] = {
    {"elephant", "meshes/elephant.off"}, {"fandisk", "meshes/fandisk.off"}, {"bull", "meshes/corpus/cgal/bull.off"}};

struct Scenario {
  const char* name;
  double gap;  // the wanted distance, a fraction of the diagonal; 0: touching
};
const Scenario kScenarios[] = {{"touching", 0.0}, {"near", 0.01}, {"apart", 0.2}};

std::string source_path(const char* path) { return std::string(TIGHTBVH_SOURCE_DIR) + "/" + path; }

#ifdef TIGHTBVH_SHAPE_BULLET
// Bullet's static triangle mesh over the same triangles; Bullet keeps pointers into the arrays.
struct BulletMesh {
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> array;
  std::unique_ptr<btBvhTriangleMeshShape> shape;
  btCollisionObject object;

  explicit BulletMesh(const tightbvh::Mesh& mesh) {
    for (const Vec3& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
    for (const auto& t : mesh.triangles)
      indices.insert(indices.end(), {static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])});
    array = std::make_unique<btTriangleIndexVertexArray>(
        static_cast<int>(mesh.triangles.size()), indices.data(), static_cast<int>(3 * sizeof(int)),
        static_cast<int>(mesh.vertices.size()), vertices.data(), static_cast<int>(3 * sizeof(btScalar)));
    shape = std::make_unique<btBvhTriangleMeshShape>(array.get(), true);
    shape->setMargin(0);  // exact geometry, as every engine here
    object.setCollisionShape(shape.get());
  }
};
#endif

struct MeshData {
  tightbvh::ModelPtr model;
  std::shared_ptr<FclMesh> fcl;
#ifdef TIGHTBVH_SHAPE_BULLET
  std::shared_ptr<BulletMesh> bullet;
#endif
  double diagonal = 0.0;
};

const MeshData& get_mesh(const MeshEntry& entry) {
  static std::map<std::string, MeshData> meshes;
  if (auto it = meshes.find(entry.name); it != meshes.end()) return it->second;
  MeshData& m = meshes[entry.name];
  m.model = tightbvh::make_model(tightbvh::load_mesh(source_path(entry.path)));
  const tightbvh::Mesh& mesh = m.model->mesh();
  Vec3 lo = mesh.vertices[0], hi = lo;
  for (const Vec3& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  m.diagonal = (hi - lo).norm();
  // FCL's own tree (its default splitter and fitter), as an FCL user builds it.
  m.fcl = std::make_shared<FclMesh>();
  std::vector<fcl::Vector3d> vertices(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  m.fcl->beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size()));
  m.fcl->addSubModel(vertices, triangles);
  m.fcl->endModel();
  m.fcl->computeLocalAABB();
#ifdef TIGHTBVH_SHAPE_BULLET
  m.bullet = std::make_shared<BulletMesh>(mesh);
#endif
  return m;
}

// The shapes, with sizes 5-10% of the diagonal d, their FCL twins and how far they reach from
// their center.
tightbvh::Sphere make_shape(tightbvh::Sphere*, std::mt19937_64& rng, double d) {
  return tightbvh::Sphere(std::uniform_real_distribution<double>(0.025, 0.05)(rng) * d);
}
tightbvh::Box make_shape(tightbvh::Box*, std::mt19937_64& rng, double d) {
  std::uniform_real_distribution<double> side(0.05 * d, 0.1 * d);
  const double x = side(rng), y = side(rng), z = side(rng);
  return tightbvh::Box(x, y, z);
}
tightbvh::Capsule make_shape(tightbvh::Capsule*, std::mt19937_64& rng, double d) {
  const double length = std::uniform_real_distribution<double>(0.05, 0.1)(rng) * d;
  return tightbvh::Capsule(length / 4.0, length);
}
tightbvh::Cylinder make_shape(tightbvh::Cylinder*, std::mt19937_64& rng, double d) {
  const double length = std::uniform_real_distribution<double>(0.05, 0.1)(rng) * d;
  return tightbvh::Cylinder(length / 4.0, length);
}
// The hull of 24 points on an ellipsoid of semi-axes 2.5-5% of the diagonal (about 40 faces).
tightbvh::Convex make_shape(tightbvh::Convex*, std::mt19937_64& rng, double d) {
  std::uniform_real_distribution<double> axis(0.025 * d, 0.05 * d);
  const Vec3 semi(axis(rng), axis(rng), axis(rng));
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Vec3> points;
  for (int i = 0; i < 24; ++i) points.push_back(Vec3(n(rng), n(rng), n(rng)).normalized().cwiseProduct(semi));
  return tightbvh::Convex(points);
}
std::shared_ptr<fcl::CollisionGeometryd> to_fcl(const tightbvh::Sphere& s) {
  return std::make_shared<fcl::Sphered>(s.radius);
}
std::shared_ptr<fcl::CollisionGeometryd> to_fcl(const tightbvh::Box& s) {
  return std::make_shared<fcl::Boxd>(s.size.x(), s.size.y(), s.size.z());
}
std::shared_ptr<fcl::CollisionGeometryd> to_fcl(const tightbvh::Capsule& s) {
  return std::make_shared<fcl::Capsuled>(s.radius, s.length);
}
#ifdef TIGHTBVH_SHAPE_BULLET
std::shared_ptr<btCollisionShape> to_bullet(const tightbvh::Sphere& s) { return std::make_shared<btSphereShape>(s.radius); }
std::shared_ptr<btCollisionShape> to_bullet(const tightbvh::Box& s) {
  auto box = std::make_shared<btBoxShape>(btVector3(0.5 * s.size.x(), 0.5 * s.size.y(), 0.5 * s.size.z()));
  box->setMargin(0);  // keeps the outer size (btBoxShape::setMargin)
  return box;
}
std::shared_ptr<btCollisionShape> to_bullet(const tightbvh::Capsule& s) {
  return std::make_shared<btCapsuleShapeZ>(s.radius, s.length);  // height: the axis segment, as FCL's lz
}
btTransform to_bullet(const Pose& pose) {
  const tightbvh::Mat3& r = pose.rotation;
  return btTransform(btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                     btVector3(pose.translation.x(), pose.translation.y(), pose.translation.z()));
}
#endif

std::shared_ptr<fcl::CollisionGeometryd> to_fcl(const tightbvh::Cylinder& s) {
  return std::make_shared<fcl::Cylinderd>(s.radius, s.length);
}
std::shared_ptr<fcl::CollisionGeometryd> to_fcl(const tightbvh::Convex& s) {
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>(s.vertices.begin(), s.vertices.end());
  auto faces = std::make_shared<std::vector<int>>();  // FCL's layout: the count, then the indices
  for (const auto& f : s.faces)
    faces->insert(faces->end(), {3, static_cast<int>(f[0]), static_cast<int>(f[1]), static_cast<int>(f[2])});
  return std::make_shared<fcl::Convexd>(vertices, static_cast<int>(s.faces.size()), faces);
}
#ifdef TIGHTBVH_SHAPE_BULLET
std::shared_ptr<btCollisionShape> to_bullet(const tightbvh::Cylinder& s) {
  auto cylinder = std::make_shared<btCylinderShapeZ>(btVector3(s.radius, s.radius, 0.5 * s.length));
  cylinder->setMargin(0);  // keeps the outer size, as the box's
  return cylinder;
}
std::shared_ptr<btCollisionShape> to_bullet(const tightbvh::Convex& s) {
  auto hull = std::make_shared<btConvexHullShape>();
  for (const Vec3& p : s.vertices) hull->addPoint(btVector3(p.x(), p.y(), p.z()), false);
  hull->recalcLocalAabb();
  hull->setMargin(0);
  return hull;
}
#endif

double reach(const tightbvh::Sphere& s) { return s.radius; }
double reach(const tightbvh::Cylinder& s) { return std::hypot(s.radius, 0.5 * s.length); }
double reach(const tightbvh::Convex& s) {
  double r = 0.0;
  for (const Vec3& v : s.vertices) r = std::max(r, v.norm());
  return r;
}
double reach(const tightbvh::Box& s) { return 0.5 * s.size.norm(); }
double reach(const tightbvh::Capsule& s) { return 0.5 * s.length + s.radius; }

fcl::Transform3d to_fcl(const Pose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.rotation;
  tf.translation() = pose.translation;
  return tf;
}

template <class S>
struct Case {
  const MeshData* mesh = nullptr;
  std::vector<S> shapes;
  std::vector<Pose> poses;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> fcl_shapes;
  std::vector<fcl::Transform3d> fcl_poses;
#ifdef TIGHTBVH_SHAPE_BULLET
  std::vector<std::shared_ptr<btCollisionShape>> bullet_shapes;
#endif
  std::vector<bool> hits;          // collide_brute_force
  std::vector<double> distances;   // distance_brute_force
};

// kPoses poses of random shapes of kind S: the center on a random point of a random triangle
// (touching), or moved off it along the triangle's normal until the exact distance is within 20%
// of the scenario's gap.
template <class S>
const Case<S>& get_case(const MeshEntry& entry, const Scenario& scenario) {
  static std::map<std::string, Case<S>> cases;
  const std::string key = std::string(entry.name) + "/" + scenario.name;
  if (auto it = cases.find(key); it != cases.end()) return it->second;
  Case<S>& c = cases[key];
  c.mesh = &get_mesh(entry);
  const tightbvh::Model& model = *c.mesh->model;
  const tightbvh::Mesh& mesh = model.mesh();
  const double d = c.mesh->diagonal, gap = scenario.gap * d;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int attempt = 0; c.poses.size() < kPoses && attempt < 100 * static_cast<int>(kPoses); ++attempt) {
    const auto t = static_cast<std::size_t>(u(rng) * static_cast<double>(mesh.triangles.size())) % mesh.triangles.size();
    const auto [a, b, p] = mesh.corners(t);
    Vec3 normal = (b - a).cross(p - a);
    if (!(normal.norm() > 0.0)) continue;
    normal.normalize();
    double x = u(rng), y = u(rng);
    if (x + y > 1.0) x = 1.0 - x, y = 1.0 - y;
    const Vec3 on_surface = a + x * (b - a) + y * (p - a);
    Pose pose;
    pose.rotation = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
    const S shape = make_shape(static_cast<S*>(nullptr), rng, d);
    bool accepted = gap == 0.0;
    pose.translation = on_surface;
    if (!accepted) {
      double offset = gap + reach(shape);
      for (int step = 0; step < 6 && offset > 0.0 && !accepted; ++step) {
        pose.translation = on_surface + offset * normal;
        const double got = tightbvh::distance(shape, pose, model, Pose::identity()).distance;
        accepted = std::abs(got - gap) <= 0.2 * gap;
        offset += gap - got;
      }
    }
    if (!accepted) continue;
    c.shapes.push_back(shape);
    c.poses.push_back(pose);
    c.fcl_shapes.push_back(to_fcl(shape));
    c.fcl_poses.push_back(to_fcl(pose));
#ifdef TIGHTBVH_SHAPE_BULLET
    c.bullet_shapes.push_back(to_bullet(shape));
#endif
    c.hits.push_back(tightbvh::collide_brute_force(shape, pose, mesh, Pose::identity()).hit);
    c.distances.push_back(tightbvh::distance_brute_force(shape, pose, mesh, Pose::identity()).distance);
  }
  return c;
}

// Enough poses were found; the counter touching_poses: how many touch (brute force).
template <class S>
bool usable(benchmark::State& state, const Case<S>& c) {
  if (c.poses.size() < kPoses) {
    state.SkipWithError(("only " + std::to_string(c.poses.size()) + " poses found").c_str());
    return false;
  }
  const auto touching = static_cast<std::size_t>(std::count(c.hits.begin(), c.hits.end(), true));
  state.counters["touching_poses"] = static_cast<double>(touching);
  return true;
}

void check_hits(benchmark::State& state, const std::vector<bool>& got, const std::vector<bool>& want) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < got.size(); ++i) wrong += got[i] == want[i] ? 0 : 1;
  if (wrong > 0) state.SkipWithError(("wrong yes/no on " + std::to_string(wrong) + " poses").c_str());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * got.size()));
}

template <class S>
void tightbvh_collide(benchmark::State& state, const MeshEntry& entry, const Scenario& scenario) {
  const Case<S>& c = get_case<S>(entry, scenario);
  if (!usable(state, c)) return;
  const tightbvh::Model& model = *c.mesh->model;
  std::vector<bool> got(c.poses.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < c.poses.size(); ++i)
      got[i] = tightbvh::collide(c.shapes[i], c.poses[i], model, Pose::identity()).hit;
  double triangles = 0.0;
  for (std::size_t i = 0; i < c.poses.size(); ++i)
    triangles += static_cast<double>(
        tightbvh::collide(c.shapes[i], c.poses[i], model, Pose::identity()).stats.triangle_tests);
  state.counters["triangles_per_pose"] = triangles / static_cast<double>(c.poses.size());
  check_hits(state, got, c.hits);
}

template <class S>
void fcl_collide(benchmark::State& state, const MeshEntry& entry, const Scenario& scenario) {
  const Case<S>& c = get_case<S>(entry, scenario);
  if (!usable(state, c)) return;
  fcl::CollisionRequestd request;
  request.num_max_contacts = 1;
  request.enable_contact = false;
  fcl::CollisionResultd result;
  const fcl::Transform3d identity = fcl::Transform3d::Identity();
  std::vector<bool> got(c.poses.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < c.poses.size(); ++i) {
      result.clear();
      fcl::collide(c.mesh->fcl.get(), identity, c.fcl_shapes[i].get(), c.fcl_poses[i], request, result);
      got[i] = result.isCollision();
    }
  check_hits(state, got, c.hits);
}

#ifdef TIGHTBVH_SHAPE_BULLET
// Whether contactPairTest reported a point at distance <= 0 (Bullet's contact points; points at a
// positive distance are closest points, not contacts).
struct AnyContact final : btCollisionWorld::ContactResultCallback {
  bool any = false;
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*,
                           int, int) override {
    if (cp.getDistance() <= 0) any = true;
    return 0;
  }
};

template <class S>
void bullet_collide(benchmark::State& state, const MeshEntry& entry, const Scenario& scenario) {
  const Case<S>& c = get_case<S>(entry, scenario);
  if (!usable(state, c)) return;
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &config);
  btCollisionObject& mesh = c.mesh->bullet->object;
  btCollisionObject shape;
  std::vector<bool> got(c.poses.size());
  std::vector<btTransform> poses;
  for (const Pose& pose : c.poses) poses.push_back(to_bullet(pose));
  for (auto _ : state)
    for (std::size_t i = 0; i < c.poses.size(); ++i) {
      shape.setCollisionShape(c.bullet_shapes[i].get());
      shape.setWorldTransform(poses[i]);
      AnyContact contact;
      world.contactPairTest(&mesh, &shape, contact);
      got[i] = contact.any;
    }
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < got.size(); ++i) wrong += got[i] == c.hits[i] ? 0 : 1;
  state.counters["bullet_wrong_poses"] = static_cast<double>(wrong);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * got.size()));
}
#endif

// Relative error of a distance against the brute force's (absolute, relative to the diagonal, when
// the brute force says 0).
double relative_error(double got, double want, double diagonal) {
  return std::abs(got - want) / (want > 0.0 ? want : diagonal);
}

template <class S>
void tightbvh_distance(benchmark::State& state, const MeshEntry& entry, const Scenario& scenario) {
  const Case<S>& c = get_case<S>(entry, scenario);
  if (!usable(state, c)) return;
  const tightbvh::Model& model = *c.mesh->model;
  std::vector<double> got(c.poses.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < c.poses.size(); ++i)
      got[i] = tightbvh::distance(c.shapes[i], c.poses[i], model, Pose::identity()).distance;
  std::vector<bool> hits;
  double worst = 0.0, triangles = 0.0, nodes = 0.0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    hits.push_back(got[i] == 0.0);
    worst = std::max(worst, relative_error(got[i], c.distances[i], c.mesh->diagonal));
    const tightbvh::DistanceStats stats =
        tightbvh::distance(c.shapes[i], c.poses[i], model, Pose::identity()).stats;
    triangles += static_cast<double>(stats.triangle_pairs);
    nodes += static_cast<double>(stats.node_pairs);
  }
  state.counters["max_rel_error"] = worst;
  state.counters["triangles_per_pose"] = triangles / static_cast<double>(got.size());
  state.counters["nodes_per_pose"] = nodes / static_cast<double>(got.size());
  if (worst > 1e-12) state.SkipWithError("a distance differs from distance_brute_force by more than 1e-12 relative");
  check_hits(state, hits, c.hits);
}

template <class S>
void fcl_distance(benchmark::State& state, const MeshEntry& entry, const Scenario& scenario) {
  const Case<S>& c = get_case<S>(entry, scenario);
  if (!usable(state, c)) return;
  fcl::DistanceRequestd request;
  fcl::DistanceResultd result;
  const fcl::Transform3d identity = fcl::Transform3d::Identity();
  std::vector<double> got(c.poses.size());
  for (auto _ : state)
    for (std::size_t i = 0; i < c.poses.size(); ++i) {
      result.clear();
      fcl::distance(c.mesh->fcl.get(), identity, c.fcl_shapes[i].get(), c.fcl_poses[i], request, result);
      got[i] = std::max(0.0, result.min_distance);  // FCL reports a touching pair as <= 0
    }
  double worst = 0.0;
  for (std::size_t i = 0; i < got.size(); ++i)
    worst = std::max(worst, relative_error(got[i], c.distances[i], c.mesh->diagonal));
  state.counters["fcl_max_rel_error"] = worst;
  if (worst > kFclTolerance)
    state.SkipWithError(("FCL's distance is off by " + std::to_string(worst) + " relative").c_str());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * got.size()));
}

template <class S>
void register_shape(const char* shape) {
  for (const MeshEntry& entry : kMeshes) {
    if (!std::filesystem::exists(source_path(entry.path))) continue;  // the corpus needs meshes/fetch-corpus
    for (const Scenario& scenario : kScenarios) {
      const std::string suffix = std::string(shape) + "/" + entry.name + "/" + scenario.name;
      benchmark::RegisterBenchmark(("ShapeCollide/tightbvh/" + suffix).c_str(), tightbvh_collide<S>, entry, scenario)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("ShapeCollide/fcl/" + suffix).c_str(), fcl_collide<S>, entry, scenario)
          ->Unit(benchmark::kMicrosecond);
#ifdef TIGHTBVH_SHAPE_BULLET
      benchmark::RegisterBenchmark(("ShapeCollide/bullet/" + suffix).c_str(), bullet_collide<S>, entry, scenario)
          ->Unit(benchmark::kMicrosecond);
#endif
      benchmark::RegisterBenchmark(("ShapeDistance/tightbvh/" + suffix).c_str(), tightbvh_distance<S>, entry,
                                   scenario)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("ShapeDistance/fcl/" + suffix).c_str(), fcl_distance<S>, entry, scenario)
          ->Unit(benchmark::kMicrosecond);
    }
  }
}

[[maybe_unused]] const bool registered = [] {
  register_shape<tightbvh::Sphere>("sphere");
  register_shape<tightbvh::Box>("box");
  register_shape<tightbvh::Capsule>("capsule");
  register_shape<tightbvh::Cylinder>("cylinder");
  register_shape<tightbvh::Convex>("convex");
  return true;
}();

}  // namespace
