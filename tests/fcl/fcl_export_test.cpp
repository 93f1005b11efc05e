// FCL export: the exported BVHModel holds our topology and our boxes, every box contains its
// triangles, and FCL's collide on it returns the same pairs as FCL's own model and our collide.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <random>
#include <set>

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>
#include <fcl/narrowphase/distance.h>

#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/fcl/export.hpp"

namespace tightbvh {
namespace {

using Pairs = std::set<std::pair<int, int>>;
namespace fs = std::filesystem;

fs::path source_dir() { return TIGHTBVH_SOURCE_DIR; }

const Mesh& shipped(const std::string& name) {
  static std::map<std::string, Mesh> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, load_mesh(source_dir() / "meshes" / name)).first;
  return it->second;
}

// The first `count` triangles of a shipped mesh: the slow fitters (exact, approx-snap) make
// whole-mesh trees too slow for a unit test, and a contiguous patch keeps the geometry real.
const Mesh& patch(const std::string& name, std::size_t count = 600) {
  static std::map<std::string, Mesh> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    Mesh m = shipped(name);
    m.triangles.resize(std::min(count, m.triangles.size()));
    it = cache.emplace(name, std::move(m)).first;
  }
  return it->second;
}

// The fitters whose trees are exported in these tests. approx-snap is left out: its boxes take
// the same export path as exact's, but each node costs an exact box of a snapped hull up to 8x
// larger (seconds for a 20-triangle patch); its containment is tested in tests/fit and tests/tree.
std::vector<FitMethod> available_fitters() {
  return {FitMethod::aabb, FitMethod::pca,  FitMethod::pca_vertex, FitMethod::diameter,
          FitMethod::approx, FitMethod::exact, FitMethod::eberly2015};
}

// exact costs milliseconds per node: it gets smaller patches.
bool slow(FitMethod m) { return m == FitMethod::exact || m == FitMethod::eberly2015; }

Tree build_tree(const Mesh& mesh, FitMethod method, std::uint32_t leaf_size) {
  BuildOptions o;
  o.fitter = method;
  o.leaf_size = leaf_size;
  o.threads = 1;
  return build(mesh, o);
}

FclExportOptions export_options(FitMethod method) {
  FclExportOptions o;
  o.fit.method = method;
  return o;
}

fcl::Transform3<double> to_fcl(const Pose& p) {
  fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
  tf.linear() = p.rotation;
  tf.translation() = p.translation;
  return tf;
}

// B placed near A: random rotation, B's center within `reach` of A's center.
std::vector<Pose> random_poses(const Mesh& a, const Mesh& b, int count, double reach, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, 1);
  const Aabb ba = bounds_of(a.vertices), bb = bounds_of(b.vertices);
  std::vector<Pose> out;
  for (int i = 0; i < count; ++i) {
    Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    const Vec3 offset = Vec3(n(rng), n(rng), n(rng)).normalized() * reach * 0.5 * ba.diagonal() *
                        std::uniform_real_distribution<double>(0, 1)(rng);
    const Mat3 r = q.toRotationMatrix();
    out.push_back({r, ba.center() + offset - r * bb.center()});
  }
  return out;
}

template <class BV>
Pairs fcl_pairs(const fcl::BVHModel<BV>& a, const fcl::BVHModel<BV>& b, const Pose& pose) {
  fcl::CollisionRequest<double> request(std::numeric_limits<std::size_t>::max(), false);
  fcl::CollisionResult<double> result;
  fcl::collide(&a, fcl::Transform3<double>::Identity(), &b, to_fcl(pose), request, result);
  Pairs out;
  for (std::size_t i = 0; i < result.numContacts(); ++i)
    out.emplace(result.getContact(i).b1, result.getContact(i).b2);
  return out;
}

template <class BV>
std::shared_ptr<fcl::BVHModel<BV>> fcl_own(const Mesh& mesh) {
  auto m = std::make_shared<fcl::BVHModel<BV>>();
  std::vector<fcl::Vector3<double>> v(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> t;
  for (const auto& tri : mesh.triangles) t.emplace_back(tri[0], tri[1], tri[2]);
  m->beginModel();
  m->addSubModel(v, t);
  m->endModel();
  return m;
}

Pairs our_pairs(const Tree& ta, const Mesh& a, const Tree& tb, const Mesh& b, const Pose& pose) {
  QueryOptions o;
  o.mode = QueryMode::all_pairs;
  Pairs out;
  for (const auto& p : collide(ta, a, Pose::identity(), tb, b, pose, o).pairs) out.emplace(p.a, p.b);
  return out;
}

// Corners of the triangles under FCL node `i`.
template <class BV>
void subtree_corners(const fcl::BVHModel<BV>& m, int i, std::vector<Vec3>& out) {
  const auto& n = m.getBV(i);
  if (n.isLeaf()) {
    const fcl::Triangle& t = m.tri_indices[n.primitiveId()];
    for (int k = 0; k < 3; ++k) out.push_back(m.vertices[t[k]]);
    return;
  }
  subtree_corners(m, n.leftChild(), out);
  subtree_corners(m, n.rightChild(), out);
}

double tolerance_for(const fcl::OBB<double>& b) {
  return 1e-9 * std::max({b.extent.maxCoeff(), b.To.cwiseAbs().maxCoeff(), 1e-300});
}

bool obb_contains(const fcl::OBB<double>& b, const Vec3& p) {
  const Vec3 q = b.axis.transpose() * (p - b.To);
  return (q.cwiseAbs().array() <= b.extent.array() + tolerance_for(b)).all();
}

bool rss_contains(const fcl::RSS<double>& r, const Vec3& p, double tol) {
  const Vec3 q = r.axis.transpose() * (p - r.To);  // rectangle [0,l0] x [0,l1] in z = 0
  const double dx = std::max({0.0, -q.x(), q.x() - r.l[0]}), dy = std::max({0.0, -q.y(), q.y() - r.l[1]});
  return std::sqrt(dx * dx + dy * dy + q.z() * q.z()) <= r.r + tol;
}

// FCL's tree shape: 2n-1 nodes, root 0, children adjacent, one triangle per leaf, every
// triangle in exactly one leaf, num_primitives consistent.
template <class BV>
void expect_fcl_shape(const fcl::BVHModel<BV>& m, std::size_t triangles) {
  ASSERT_EQ(m.getNumBVs(), int(2 * triangles - 1));
  std::vector<int> seen(triangles, 0);
  std::vector<int> stack{0};
  int visited = 0;
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    ++visited;
    const auto& n = m.getBV(i);
    if (n.isLeaf()) {
      EXPECT_EQ(n.num_primitives, 1);
      ASSERT_GE(n.primitiveId(), 0);
      ASSERT_LT(n.primitiveId(), int(triangles));
      ++seen[n.primitiveId()];
    } else {
      ASSERT_GT(n.leftChild(), i);
      ASSERT_EQ(n.rightChild(), n.leftChild() + 1);
      EXPECT_EQ(n.num_primitives, m.getBV(n.leftChild()).num_primitives + m.getBV(n.rightChild()).num_primitives);
      stack.push_back(n.leftChild());
      stack.push_back(n.rightChild());
    }
  }
  EXPECT_EQ(visited, m.getNumBVs());
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(triangles));
}

TEST(FclExport, ShapeAndContainmentEveryFitterAndLeafSize) {
  for (const std::string name : {"elephant.off", "knot1.off"}) {
    for (FitMethod method : available_fitters()) {
      const Mesh& mesh = patch(name, slow(method) ? 60 : 600);
      for (std::uint32_t leaf_size : {1u, 4u, 16u}) {
        if (slow(method) && leaf_size != 4) continue;
        SCOPED_TRACE(name + " fitter " + std::string(to_string(method)) + " leaf " + std::to_string(leaf_size));
        const Tree tree = build_tree(mesh, method, leaf_size);
        const auto obb = to_fcl(tree, mesh, export_options(method));
        const auto obbrss = to_fcl_obbrss(tree, mesh, export_options(method));
        const auto rss = to_fcl_rss(tree, mesh, export_options(method));
        expect_fcl_shape(*obb, mesh.triangles.size());
        expect_fcl_shape(*obbrss, mesh.triangles.size());
        expect_fcl_shape(*rss, mesh.triangles.size());
        // Our root box is FCL's root box.
        const fcl::OBB<double> root = to_fcl_obb(tree.nodes[0].box.obb());
        EXPECT_TRUE(obb->getBV(0).bv.To.isApprox(root.To) && obb->getBV(0).bv.extent.isApprox(root.extent));
        int bad_obb = 0, bad_rss = 0, bad_obbrss = 0, bad_rss_model = 0;
        std::vector<Vec3> corners;
        for (int i = 0; i < obb->getNumBVs(); ++i) {
          corners.clear();
          subtree_corners(*obb, i, corners);
          for (const Vec3& p : corners) bad_obb += obb_contains(obb->getBV(i).bv, p) ? 0 : 1;
          corners.clear();
          subtree_corners(*obbrss, i, corners);
          const auto& bv = obbrss->getBV(i).bv;
          const double tol = tolerance_for(bv.obb);
          for (const Vec3& p : corners) {
            bad_obbrss += obb_contains(bv.obb, p) ? 0 : 1;
            bad_rss += rss_contains(bv.rss, p, tol) ? 0 : 1;
          }
          corners.clear();
          subtree_corners(*rss, i, corners);
          for (const Vec3& p : corners) bad_rss_model += rss_contains(rss->getBV(i).bv, p, tol) ? 0 : 1;
        }
        EXPECT_EQ(bad_obb, 0);
        EXPECT_EQ(bad_obbrss, 0);
        EXPECT_EQ(bad_rss, 0);
        EXPECT_EQ(bad_rss_model, 0);
      }
    }
  }
}

// With one triangle per leaf no node is added: walking both trees together, every FCL node is
// our node (same children, same leaf triangle, same box).
TEST(FclExport, WithLeafSizeOneTopologyAndBoxesAreOurs) {
  const Mesh& mesh = patch("knot1.off");
  for (FitMethod method : available_fitters()) {
    if (slow(method)) continue;  // covered by the containment test above
    SCOPED_TRACE(std::string(to_string(method)));
    const Tree tree = build_tree(mesh, method, 1);
    const auto model = to_fcl(tree, mesh, export_options(method));
    ASSERT_EQ(std::size_t(model->getNumBVs()), tree.nodes.size());
    std::vector<std::pair<std::uint32_t, int>> stack{{0u, 0}};  // (our node, FCL node)
    int compared = 0;
    while (!stack.empty()) {
      const auto [ours, theirs] = stack.back();
      stack.pop_back();
      ++compared;
      const Node& n = tree.nodes[ours];
      const auto& f = model->getBV(theirs);
      const fcl::OBB<double> expected = to_fcl_obb(n.box.obb());
      ASSERT_EQ(f.bv.To, expected.To);
      ASSERT_EQ(f.bv.extent, expected.extent);
      ASSERT_EQ(f.bv.axis, expected.axis);
      ASSERT_EQ(n.is_leaf(), f.isLeaf());
      if (n.is_leaf()) {
        ASSERT_EQ(f.primitiveId(), int(tree.triangle_order[n.first]));
      } else {
        stack.push_back({n.first, f.leftChild()});
        stack.push_back({n.first + 1, f.rightChild()});
      }
    }
    EXPECT_EQ(compared, model->getNumBVs());
  }
}

TEST(FclExport, RssContainsRandomPoints) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Vec3> points;
    const Vec3 scale(std::exp(n(rng)), std::exp(n(rng)), std::exp(n(rng)));
    for (int i = 0; i < 20; ++i) points.push_back(Vec3(n(rng), n(rng), n(rng)).cwiseProduct(scale));
    FitOptions o;
    o.method = FitMethod::aabb;
    const Obb box = fit_points(points, o);
    const fcl::RSS<double> rss = fit_rss(box, points);
    for (const Vec3& p : points) ASSERT_TRUE(rss_contains(rss, p, 1e-9 * scale.maxCoeff())) << trial;
    EXPECT_GE(rss.l[0], rss.l[1]);
    EXPECT_NEAR(rss.axis.determinant(), 1.0, 1e-12);
  }
}

TEST(FclExport, SamePairsAsFclOwnModelsAndOurCollideEveryFitter) {
  const Mesh& a = patch("elephant.off", 1500);
  const Mesh& b = patch("knot1.off", 1500);
  const auto own_obb_a = fcl_own<fcl::OBB<double>>(a), own_obb_b = fcl_own<fcl::OBB<double>>(b);
  const auto own_rss_a = fcl_own<fcl::OBBRSS<double>>(a), own_rss_b = fcl_own<fcl::OBBRSS<double>>(b);
  const auto poses = random_poses(a, b, 12, 1.0, 42);
  std::vector<Pairs> reference;
  std::size_t total = 0;
  for (const Pose& p : poses) {
    reference.push_back(fcl_pairs(*own_obb_a, *own_obb_b, p));
    EXPECT_EQ(fcl_pairs(*own_rss_a, *own_rss_b, p), reference.back());
    total += reference.back().size();
  }
  ASSERT_GT(total, 0u) << "the poses must produce contacts for this test to mean anything";
  for (FitMethod method : available_fitters()) {
    // The slow fitters' trees are tested on the same poses with B's first 300 triangles only.
    SCOPED_TRACE(std::string("fitter ") + std::string(to_string(method)));
    if (slow(method)) {
      const Mesh& small_b = patch("knot1.off", 300);
      const Tree ta = build_tree(a, FitMethod::pca, 4), tb = build_tree(small_b, method, 4);
      const auto eb = to_fcl(tb, small_b, export_options(method));
      const auto ea = to_fcl(ta, a, export_options(FitMethod::pca));
      const auto own_b = fcl_own<fcl::OBB<double>>(small_b);
      for (const Pose& p : poses) {
        const Pairs expected = fcl_pairs(*own_obb_a, *own_b, p);
        EXPECT_EQ(fcl_pairs(*ea, *eb, p), expected);
        EXPECT_EQ(our_pairs(ta, a, tb, small_b, p), expected);
      }
      continue;
    }
    const Tree ta = build_tree(a, method, 4), tb = build_tree(b, method, 4);
    const auto ea = to_fcl(ta, a, export_options(method)), eb = to_fcl(tb, b, export_options(method));
    const auto ra = to_fcl_obbrss(ta, a, export_options(method)), rb = to_fcl_obbrss(tb, b, export_options(method));
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(fcl_pairs(*ea, *eb, poses[i]), reference[i]) << "pose " << i;
      EXPECT_EQ(fcl_pairs(*ra, *rb, poses[i]), reference[i]) << "pose " << i;
      EXPECT_EQ(our_pairs(ta, a, tb, b, poses[i]), reference[i]) << "pose " << i;
    }
  }
}

TEST(FclExport, DistanceOnExportedObbRssEqualsFclOwn) {
  // FCL's distance queries use the RSS half of OBBRSS: a wrong RSS would prune the true minimum.
  const Mesh& a = shipped("elephant.off");
  const Mesh& b = shipped("knot1.off");
  const auto own_a = fcl_own<fcl::OBBRSS<double>>(a), own_b = fcl_own<fcl::OBBRSS<double>>(b);
  const Tree ta = build_tree(a, FitMethod::pca, 4), tb = build_tree(b, FitMethod::pca, 4);
  const auto ea = to_fcl_obbrss(ta, a), eb = to_fcl_obbrss(tb, b);
  for (const Pose& p : random_poses(a, b, 10, 3.0, 9)) {
    fcl::DistanceRequest<double> request;
    fcl::DistanceResult<double> own, exported;
    fcl::distance(own_a.get(), fcl::Transform3<double>::Identity(), own_b.get(), to_fcl(p), request, own);
    fcl::distance(ea.get(), fcl::Transform3<double>::Identity(), eb.get(), to_fcl(p), request, exported);
    EXPECT_NEAR(exported.min_distance, own.min_distance, 1e-9 * bounds_of(a.vertices).diagonal());
  }
}

// FCL's own fcl::distance on our exported RSS and OBBRSS trees equals our
// distance() (within 1e-9 relative, 1e-12 of the scale absolute), from touching to separated.
TEST(FclExport, FclDistanceOnExportedTreesEqualsOurs) {
  const Mesh& a = shipped("elephant.off");
  const Mesh& b = shipped("knot1.off");
  const double scale = std::max(bounds_of(a.vertices).diagonal(), bounds_of(b.vertices).diagonal());
  for (const FitMethod method : {FitMethod::pca, FitMethod::approx}) {
    SCOPED_TRACE(std::string("fitter ") + std::string(to_string(method)));
    const Tree ta = build_tree(a, method, 1), tb = build_tree(b, method, 1);
    const auto rss_a = to_fcl_rss(ta, a, export_options(method)), rss_b = to_fcl_rss(tb, b, export_options(method));
    const auto obbrss_a = to_fcl_obbrss(ta, a, export_options(method));
    const auto obbrss_b = to_fcl_obbrss(tb, b, export_options(method));
    QueryWorkspace workspace;
    int separated = 0;
    for (const Pose& p : random_poses(a, b, 10, 3.0, 21)) {
      const double ours = distance(ta, a, Pose::identity(), tb, b, p, {}, workspace).distance;
      const auto fcl_distance = [&](const auto& ma, const auto& mb) {
        fcl::DistanceRequest<double> request;
        fcl::DistanceResult<double> result;
        fcl::distance(ma.get(), fcl::Transform3<double>::Identity(), mb.get(), to_fcl(p), request, result);
        return std::max(0.0, result.min_distance);  // FCL reports touching meshes as <= 0
      };
      EXPECT_NEAR(fcl_distance(rss_a, rss_b), ours, 1e-9 * ours + 1e-12 * scale);
      EXPECT_NEAR(fcl_distance(obbrss_a, obbrss_b), ours, 1e-9 * ours + 1e-12 * scale);
      separated += ours > 0.0;
    }
    EXPECT_GE(separated, 3);
    EXPECT_LE(separated, 9);
  }
}

TEST(FclExport, RejectsATreeOfAnotherMesh) {
  const Mesh& a = shipped("elephant.off");
  const Mesh& b = shipped("knot1.off");
  const Tree tree = build_tree(a, FitMethod::aabb, 4);
  EXPECT_THROW((void)to_fcl(tree, b), InputError);
  Tree broken = tree;
  broken.triangle_order[0] = broken.triangle_order[1];  // one triangle twice, one missing
  EXPECT_THROW((void)to_fcl(broken, a), InputError);
  EXPECT_THROW((void)to_fcl(Tree{}, a), InputError);
}

// Whether moving B's triangle by `tol` (axes, both normals) can change whether the pair
// touches: their distance is within `tol` of zero from either side.
bool near_touching_pair(const std::array<Vec3, 3>& ta, const std::array<Vec3, 3>& tb, const Pose& pose, double tol) {
  fcl::Vector3<double> s[3], t[3], P, Q;
  for (int k = 0; k < 3; ++k) {
    s[k] = ta[k];
    t[k] = pose.apply(tb[k]);
  }
  const auto dist = [&](const Vec3& shift) {
    fcl::Vector3<double> u[3] = {t[0] + shift, t[1] + shift, t[2] + shift};
    return fcl::detail::TriangleDistance<double>::triDistance(s, u, P, Q);
  };
  const double d = dist(Vec3::Zero());
  if (d > 0) return d <= tol;
  const Vec3 na = (s[1] - s[0]).cross(s[2] - s[0]).normalized(), nb = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  for (const Vec3& dir : {Vec3::UnitX().eval(), Vec3::UnitY().eval(), Vec3::UnitZ().eval(), na, nb})
    if (dir.allFinite() && (dist(tol * dir) > 0 || dist(-tol * dir) > 0)) return true;
  return false;
}

// On the corpus (meshes/fetch-corpus), FCL vs our collide: the same yes/no answers and pair
// sets, except pairs within 1e-9 of the mesh scale of touching, which are counted and printed.
TEST(FclExport, CorpusFclAgreesWithOursExceptNearTouching) {
  const fs::path corpus = source_dir() / "meshes" / "corpus" / "cgal";
  const std::vector<std::pair<std::string, std::string>> pairs_of_meshes{
      {"cow.off", "mushroom.off"}, {"fandisk.off", "rotor.off"}, {"homer.off", "hand.off"}, {"bull.off", "elk.off"}};
  if (!fs::exists(corpus / "cow.off")) GTEST_SKIP() << "corpus missing: run meshes/fetch-corpus";
  int near_touching = 0, compared = 0;
  for (const auto& [na, nb] : pairs_of_meshes) {
    SCOPED_TRACE(na + " vs " + nb);
    const Mesh a = load_mesh(corpus / na), b = load_mesh(corpus / nb);
    const double tol = 1e-9 * std::max(bounds_of(a.vertices).diagonal(), bounds_of(b.vertices).diagonal());
    const auto fa = fcl_own<fcl::OBB<double>>(a), fb = fcl_own<fcl::OBB<double>>(b);
    const Tree ta = build_tree(a, FitMethod::pca, 1), tb = build_tree(b, FitMethod::pca, 1);
    for (const Pose& p : random_poses(a, b, 15, 1.0, 3)) {
      const Pairs theirs = fcl_pairs(*fa, *fb, p), mine = our_pairs(ta, a, tb, b, p);
      ++compared;
      std::vector<std::pair<int, int>> diff;
      std::set_symmetric_difference(theirs.begin(), theirs.end(), mine.begin(), mine.end(), std::back_inserter(diff));
      for (const auto& [ia, ib] : diff) {
        EXPECT_TRUE(near_touching_pair(a.corners(ia), b.corners(ib), p, tol))
            << "pair (" << ia << ", " << ib << ") differs and is not within " << tol << " of touching";
        ++near_touching;
      }
      EXPECT_EQ(theirs.empty(), mine.empty());
    }
  }
  std::cout << "[ corpus  ] " << compared << " poses compared, " << near_touching
            << " differing pairs, all within 1e-9 of the mesh scale of touching\n";
  RecordProperty("near_touching_pairs", near_touching);
}

}  // namespace
}  // namespace tightbvh
