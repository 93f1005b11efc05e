// Model: built once, shared; the model overloads answer as the low-level pair queries.
#include <gtest/gtest.h>

#include <random>

#include "scene_fixtures.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"

namespace tightbvh {
namespace {

using scene_test::mixed_models;
using scene_test::random_pose;

TEST(Model, BoundsContainEveryVertexWithOrthonormalAxes) {
  for (const ModelPtr& model : mixed_models()) {
    const Obb& box = model->bounds();
    EXPECT_LT((box.axes.transpose() * box.axes - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    for (const Vec3& v : model->mesh().vertices) EXPECT_TRUE(box.contains(v));
    EXPECT_GT(model->bytes(), model->mesh().vertices.size() * sizeof(Vec3));
  }
}

TEST(Model, ClosednessComputedOnce) {
  const auto models = mixed_models();
  EXPECT_TRUE(models[0]->closedness().closed);  // the box
  EXPECT_TRUE(models[1]->closedness().closed);  // the tetrahedron
  EXPECT_FALSE(models[3]->closedness().closed);  // every 40th triangle of the elephant
}

TEST(Model, FromAnExistingTreeIsValidated) {
  const Mesh mesh = scene_test::tetrahedron();
  Tree tree = build(mesh);
  const ModelPtr model = make_model(mesh, tree);
  EXPECT_EQ(model->tree().nodes.size(), tree.nodes.size());
  // A tree of another mesh: too few triangles.
  EXPECT_THROW((void)make_model(query_test::cube(), tree), InputError);
  // A box that no longer holds its triangles.
  tree.nodes[0].box.half_extents *= 0.25f;
  EXPECT_THROW((void)make_model(mesh, tree), InputError);
  EXPECT_THROW((void)make_model(Mesh{}), InputError);
}

TEST(Model, PairQueriesEqualTheLowLevelCalls) {
  const auto models = mixed_models();
  std::mt19937_64 rng(7);
  int hits = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Model& a = *models[trial % models.size()];
    const Model& b = *models[(trial / 3) % models.size()];
    const Pose pa = random_pose(rng, 1.0), pb = random_pose(rng, 1.0);
    const QueryOptions all{.mode = QueryMode::all_pairs};
    const QueryResult r = collide(a, pa, b, pb, all);
    const QueryResult low = collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, all);
    EXPECT_EQ(r.pairs, low.pairs);
    EXPECT_EQ(r.stats, low.stats);
    hits += r.hit;
    const DistanceResult d = distance(a, pa, b, pb);
    const DistanceResult dl = distance(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb);
    EXPECT_EQ(d.distance, dl.distance);
    EXPECT_EQ(d.pair, dl.pair);
  }
  EXPECT_GT(hits, 5);
  EXPECT_LT(hits, 55);
}

TEST(Model, SolidQueriesUseTheModelsClosedness) {
  const auto models = scene_test::closed_models();
  const Model& box = *models[0];
  const ModelPtr small = make_model(query_test::cube(Vec3::Constant(-0.05), 0.1));
  const QueryResult r = collide(box, Pose{}, *small, Pose{}, {.solid = true});
  EXPECT_TRUE(r.hit);
  EXPECT_EQ(r.inside, Inside::b_in_a);
  EXPECT_EQ(distance(box, Pose{}, *small, Pose{}, {.solid = true}).distance, 0.0);
  // An open model: the solid query names the mesh.
  const ModelPtr open = mixed_models()[3];
  EXPECT_THROW((void)collide(box, Pose{}, *open, Pose{}, {.solid = true}), InputError);
}

}  // namespace
}  // namespace tightbvh
