// Model: built once, shared; the model overloads answer as the low-level pair queries.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <string>

#include "scene_fixtures.hpp"
#include "tightbvh/collide_trace.hpp"
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
    // all_pairs descends the wide nodes: the same pairs, its own stats.
    const QueryOptions all{.mode = QueryMode::all_pairs};
    const QueryResult r = collide(a, pa, b, pb, all);
    const QueryResult low = collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, all);
    EXPECT_EQ(r.hit, low.hit);
    EXPECT_EQ(r.pairs, low.pairs);
    EXPECT_GE(r.stats.triangle_tests, r.pairs.size());
    hits += r.hit;
    // first_hit descends the wide nodes too: the same yes/no, and its pair is a touching one.
    const QueryResult first = collide(a, pa, b, pb, {.mode = QueryMode::first_hit});
    EXPECT_EQ(first.hit, low.hit);
    ASSERT_EQ(first.pairs.size(), first.hit ? 1u : 0u);
    if (first.hit) EXPECT_TRUE(std::binary_search(low.pairs.begin(), low.pairs.end(), first.pairs[0]));
    // So do margins: the pairs within the margin, and first_hit's yes/no.
    const QueryOptions near{.mode = QueryMode::all_pairs, .margin = 0.01};
    const QueryResult within = collide(a, pa, b, pb, near);
    const QueryResult within_low = collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, near);
    EXPECT_EQ(within.pairs, within_low.pairs);
    EXPECT_EQ(collide(a, pa, b, pb, {.mode = QueryMode::first_hit, .margin = 0.01}).hit, within_low.hit);
    // Another descend rule runs the binary descent: the same stats too.
    const QueryOptions extent{.mode = QueryMode::all_pairs, .descend = DescendRule::larger_extent};
    const QueryResult e = collide(a, pa, b, pb, extent);
    const QueryResult el = collide(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb, extent);
    EXPECT_EQ(e.pairs, el.pairs);
    EXPECT_EQ(e.stats, el.stats);
    const DistanceResult d = distance(a, pa, b, pb);
    const DistanceResult dl = distance(a.tree(), a.mesh(), pa, b.tree(), b.mesh(), pb);
    EXPECT_EQ(d.distance, dl.distance);
    EXPECT_EQ(d.pair, dl.pair);
  }
  EXPECT_GT(hits, 5);
  EXPECT_LT(hits, 55);
}

// Whole shipped meshes, many of them touching: the wide descent gives the binary descent's answers.
TEST(Model, ShippedMeshesGiveTheTreesAnswersInEveryMode) {
  const ModelPtr knot = make_model(query_test::shipped("meshes/knot1.off"));
  const ModelPtr elephant = make_model(query_test::shipped("meshes/elephant.off"));
  const Obb& kb = knot->bounds();
  const Obb& eb = elephant->bounds();
  std::mt19937_64 rng(11);
  int touching = 0;
  for (int trial = 0; trial < 24; ++trial) {
    Pose pb = random_pose(rng, 0.0);
    // Centers apart by a random fraction of the boxes' reach: deep overlap to just missing.
    const double reach = kb.half_extents.norm() + eb.half_extents.norm();
    pb.translation = kb.center - pb.rotation * eb.center +
                     std::uniform_real_distribution<double>(0.0, 0.9)(rng) * reach * Vec3::UnitX();
    const QueryOptions all{.mode = QueryMode::all_pairs};
    const QueryResult r = collide(*knot, Pose{}, *elephant, pb, all);
    const QueryResult low = collide(knot->tree(), knot->mesh(), Pose{}, elephant->tree(), elephant->mesh(), pb, all);
    EXPECT_EQ(r.pairs, low.pairs) << "trial " << trial;
    EXPECT_EQ(r.hit, !r.pairs.empty());
    touching += r.hit;
    const QueryResult first = collide(*knot, Pose{}, *elephant, pb, {.mode = QueryMode::first_hit});
    EXPECT_EQ(first.hit, r.hit) << "trial " << trial;
    if (first.hit) EXPECT_TRUE(std::binary_search(r.pairs.begin(), r.pairs.end(), first.pairs.at(0)));
    // A margin of 0.5% of the size: more pairs than touch, the same set as the trees'.
    const QueryOptions within{.mode = QueryMode::all_pairs, .margin = 0.005 * reach};
    const QueryResult w = collide(*knot, Pose{}, *elephant, pb, within);
    EXPECT_EQ(w.pairs, collide(knot->tree(), knot->mesh(), Pose{}, elephant->tree(), elephant->mesh(), pb, within).pairs)
        << "trial " << trial;
    EXPECT_GE(w.pairs.size(), r.pairs.size());
    EXPECT_EQ(collide(*knot, Pose{}, *elephant, pb, {.mode = QueryMode::first_hit, .margin = 0.005 * reach}).hit,
              !w.pairs.empty());
    // Solids and contacts are added after the wide descent as collide() adds them.
    const QueryOptions more{.mode = QueryMode::all_pairs, .solid = true, .contacts = true};
    const QueryResult m = collide(*knot, Pose{}, *elephant, pb, more);
    const QueryResult ml = collide(knot->tree(), knot->mesh(), Pose{}, elephant->tree(), elephant->mesh(), pb, more);
    EXPECT_EQ(m.hit, ml.hit) << "trial " << trial;
    EXPECT_EQ(m.inside, ml.inside) << "trial " << trial;
    EXPECT_EQ(m.pairs, low.pairs) << "trial " << trial;
    ASSERT_EQ(m.contacts.size(), ml.contacts.size()) << "trial " << trial;
    for (std::size_t i = 0; i < m.contacts.size(); ++i) {
      ASSERT_EQ(m.contacts[i].count, ml.contacts[i].count);
      EXPECT_EQ(m.contacts[i].kind, ml.contacts[i].kind);
      for (int k = 0; k < m.contacts[i].count; ++k) EXPECT_EQ(m.contacts[i].points[k], ml.contacts[i].points[k]);
    }
    EXPECT_EQ(m.curve_length, ml.curve_length);
  }
  EXPECT_GT(touching, 5);
}

// collide_trace on models records the wide descent that collide() on models makes: the same
// answer and stats, one visited pair per box test, leaf pairs named by leaves of the trees, and
// every reported triangle pair inside a leaf pair whose outcome is a hit.
TEST(Model, CollideTraceIsTheWideDescent) {
  const ModelPtr knot = make_model(query_test::shipped("meshes/knot1.off"));
  const ModelPtr elephant = make_model(query_test::shipped("meshes/elephant.off"));
  const Obb& kb = knot->bounds();
  const Obb& eb = elephant->bounds();
  const double reach = kb.half_extents.norm() + eb.half_extents.norm();
  const auto leaf_holds = [](const Tree& tree, std::uint32_t node, std::uint32_t triangle) {
    const Node& n = tree.nodes[node];
    const auto begin = tree.triangle_order.begin() + n.first;
    return n.is_leaf() && std::find(begin, begin + n.count, triangle) != begin + n.count;
  };
  std::mt19937_64 rng(12);
  int hits = 0;
  for (int trial = 0; trial < 8; ++trial) {
    Pose pb = random_pose(rng, 0.0);
    pb.translation = kb.center - pb.rotation * eb.center +
                     std::uniform_real_distribution<double>(0.0, 0.8)(rng) * reach * Vec3::UnitX();
    for (const QueryOptions& o : {QueryOptions{.mode = QueryMode::all_pairs}, QueryOptions{},
                                  QueryOptions{.mode = QueryMode::all_pairs, .margin = 0.003 * reach}}) {
      const QueryResult expected = collide(*knot, Pose{}, *elephant, pb, o);
      const CollideTrace trace = collide_trace(*knot, Pose{}, *elephant, pb, o);
      const std::string where = "trial " + std::to_string(trial) + " margin " + std::to_string(o.margin);
      EXPECT_EQ(trace.result.pairs, expected.pairs) << where;  // first_hit too: the same descent
      EXPECT_EQ(trace.result.hit, expected.hit) << where;
      EXPECT_EQ(trace.result.stats, expected.stats) << where;
      EXPECT_EQ(trace.visited, expected.stats.box_tests) << where;
      ASSERT_EQ(trace.pairs.size(), trace.visited) << where;
      std::uint64_t counted = 0, hit_pairs = 0;
      for (const auto& row : trace.per_level) counted += std::accumulate(row.begin(), row.end(), std::uint64_t{0});
      EXPECT_EQ(counted, trace.visited) << where;
      EXPECT_EQ(trace.pairs.front().a, 0u);  // the roots first
      EXPECT_EQ(trace.pairs.front().b, 0u);
      for (const VisitedPair& v : trace.pairs) {
        if (v.outcome != PairOutcome::leaves && v.outcome != PairOutcome::hit) continue;
        EXPECT_TRUE(knot->tree().nodes[v.a].is_leaf() && elephant->tree().nodes[v.b].is_leaf()) << where;
        hit_pairs += v.outcome == PairOutcome::hit;
      }
      EXPECT_EQ(hit_pairs > 0, expected.hit) << where;
      for (const TrianglePair& p : expected.pairs) {
        const bool found = std::any_of(trace.pairs.begin(), trace.pairs.end(), [&](const VisitedPair& v) {
          return v.outcome == PairOutcome::hit && leaf_holds(knot->tree(), v.a, p.a) &&
                 leaf_holds(elephant->tree(), v.b, p.b);
        });
        if (!found) ADD_FAILURE() << where << ": pair " << p.a << " " << p.b << " in no hit leaf pair";
        if (!found || o.mode == QueryMode::first_hit) break;
      }
      hits += expected.hit;
    }
  }
  EXPECT_GT(hits, 6);
  // The cap keeps the prefix and counts everything; bad poses as collide().
  const CollideTrace full = collide_trace(*knot, Pose{}, *elephant, Pose{}, {.mode = QueryMode::all_pairs});
  const CollideTrace capped =
      collide_trace(*knot, Pose{}, *elephant, Pose{}, {.mode = QueryMode::all_pairs}, {.max_pairs = 10});
  ASSERT_EQ(capped.pairs.size(), 10u);
  EXPECT_EQ(capped.visited, full.visited);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(capped.pairs[i].a, full.pairs[i].a);
  Pose bad;
  bad.rotation(0, 0) = 2.0;
  EXPECT_THROW((void)collide_trace(*knot, Pose{}, *elephant, bad), InputError);
}

TEST(Model, BadPosesAreRejectedInEveryMode) {
  const auto models = mixed_models();
  Pose nan;
  nan.translation.x() = std::numeric_limits<double>::quiet_NaN();
  Pose scaled;
  scaled.rotation *= 1.01;
  Pose reflected;
  reflected.rotation(2, 2) = -1.0;
  for (const Pose& bad : {nan, scaled, reflected})
    for (const QueryMode mode : {QueryMode::first_hit, QueryMode::all_pairs}) {
      EXPECT_THROW((void)collide(*models[0], bad, *models[1], Pose{}, {.mode = mode}), InputError);
      EXPECT_THROW((void)collide(*models[0], Pose{}, *models[1], bad, {.mode = mode}), InputError);
    }
}

TEST(Model, SolidQueriesUseTheModelsClosedness) {
  const auto models = scene_test::closed_models();
  const Model& box = *models[0];
  const ModelPtr small = make_model(query_test::cube(Vec3::Constant(-0.05), 0.1));
  const QueryResult r = collide(box, Pose{}, *small, Pose{}, {.solid = true});
  EXPECT_TRUE(r.hit);
  EXPECT_EQ(r.inside, Inside::b_in_a);
  // all_pairs runs the wide descent, then the same containment test.
  const QueryResult all = collide(*small, Pose{}, box, Pose{}, {.mode = QueryMode::all_pairs, .solid = true});
  EXPECT_TRUE(all.hit);
  EXPECT_TRUE(all.pairs.empty());
  EXPECT_EQ(all.inside, Inside::a_in_b);
  EXPECT_EQ(distance(box, Pose{}, *small, Pose{}, {.solid = true}).distance, 0.0);
  // An open model: the solid query names the mesh.
  const ModelPtr open = mixed_models()[3];
  EXPECT_THROW((void)collide(box, Pose{}, *open, Pose{}, {.solid = true}), InputError);
  EXPECT_THROW((void)collide(box, Pose{}, *open, Pose{}, {.mode = QueryMode::all_pairs, .solid = true}), InputError);
  // Contacts need all_pairs and margin 0, on models as on trees; margins must be finite and >= 0.
  EXPECT_THROW((void)collide(box, Pose{}, *small, Pose{}, {.contacts = true}), InputError);
  EXPECT_THROW((void)collide(box, Pose{}, *small, Pose{}, {.mode = QueryMode::all_pairs, .margin = 0.1, .contacts = true}),
               InputError);
  for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    EXPECT_THROW((void)collide(box, Pose{}, *small, Pose{}, {.mode = QueryMode::all_pairs, .margin = bad}), InputError);
}

}  // namespace
}  // namespace tightbvh
