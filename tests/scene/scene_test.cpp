// Scene queries against brute force: the pair queries run on every object pair (every tested
// pair of a scene, every pair across two scenes, every object against the query object).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "scene_fixtures.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/scene.hpp"

namespace tightbvh {
namespace {

using scene_test::random_pose;

// ------------------------------------------------------------------ brute force

QueryResult pair_collide(const SceneObject& a, const SceneObject& b, const QueryOptions& options) {
  // The models' own pair query (model_test.cpp checks it against the trees' collide()).
  return collide(*a.model, a.pose, *b.model, b.pose, options);
}

DistanceResult pair_distance(const SceneObject& a, const SceneObject& b, const DistanceOptions& options) {
  DistanceOptions o = options;
  if (o.solid) o.closed_a = &a.model->closedness(), o.closed_b = &b.model->closedness();
  return distance(a.model->tree(), a.model->mesh(), a.pose, b.model->tree(), b.model->mesh(), b.pose, o);
}

bool filters_meet(const SceneObject& a, const SceneObject& b) { return (a.group & b.mask) && (b.group & a.mask); }

// Every object pair (a from `x`, b from `y`) a query would consider, in (a, b) order.
std::vector<std::pair<ObjectId, ObjectId>> all_pairs(const Scene& x, const Scene* y) {
  std::vector<std::pair<ObjectId, ObjectId>> pairs;
  for (const ObjectId a : x.ids()) {
    if (!y) {
      for (const ObjectId b : x.ids())
        if (a < b && x.tested(a, b)) pairs.emplace_back(a, b);
    } else {
      for (const ObjectId b : y->ids())
        if (filters_meet(x.object(a), y->object(b))) pairs.emplace_back(a, b);
    }
  }
  return pairs;
}

std::vector<ObjectPairHit> brute_collide(const Scene& x, const Scene* y, const QueryOptions& options) {
  const Scene& other = y ? *y : x;
  std::vector<ObjectPairHit> hits;
  for (const auto& [a, b] : all_pairs(x, y)) {
    QueryResult r = pair_collide(x.object(a), other.object(b), options);
    if (r.hit) hits.push_back({a, b, std::move(r)});
  }
  return hits;
}

std::vector<ObjectPairDistance> brute_within(const Scene& x, const Scene* y, double d, const DistanceOptions& options) {
  const Scene& other = y ? *y : x;
  std::vector<ObjectPairDistance> out;
  for (const auto& [a, b] : all_pairs(x, y)) {
    DistanceResult r = pair_distance(x.object(a), other.object(b), options);
    if (r.distance < d) out.push_back({a, b, std::move(r)});
  }
  return out;
}

std::optional<ObjectPairDistance> brute_nearest(const Scene& x, const Scene* y, const DistanceOptions& options) {
  const Scene& other = y ? *y : x;
  std::optional<ObjectPairDistance> best;
  for (const auto& [a, b] : all_pairs(x, y)) {
    DistanceResult r = pair_distance(x.object(a), other.object(b), options);
    if (!best || r.distance < best->result.distance) best = ObjectPairDistance{a, b, std::move(r)};
  }
  return best;
}

void expect_same(const QueryResult& r, const QueryResult& expected, const std::string& where) {
  EXPECT_EQ(r.hit, expected.hit) << where;
  EXPECT_EQ(r.pairs, expected.pairs) << where;
  EXPECT_EQ(r.inside, expected.inside) << where;
  EXPECT_EQ(r.stats, expected.stats) << where;
}

void expect_same(const std::vector<ObjectPairHit>& got, const std::vector<ObjectPairHit>& expected,
                 const std::string& where) {
  ASSERT_EQ(got.size(), expected.size()) << where;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].a, expected[i].a) << where << " #" << i;
    EXPECT_EQ(got[i].b, expected[i].b) << where << " #" << i;
    expect_same(got[i].result, expected[i].result, where + " pair " + std::to_string(got[i].a) + "-" + std::to_string(got[i].b));
  }
}

void expect_same(const std::vector<ObjectPairDistance>& got, const std::vector<ObjectPairDistance>& expected,
                 const std::string& where) {
  ASSERT_EQ(got.size(), expected.size()) << where;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].a, expected[i].a) << where << " #" << i;
    EXPECT_EQ(got[i].b, expected[i].b) << where << " #" << i;
    EXPECT_EQ(got[i].result.distance, expected[i].result.distance) << where << " #" << i;
  }
}

// ------------------------------------------------------------------ random scenes

struct RandomScene {
  std::vector<ModelPtr> models;
  Scene scene;
  std::mt19937_64 rng;
  double extent;

  RandomScene(std::vector<ModelPtr> m, std::uint64_t seed, int objects, double extent_)
      : models(std::move(m)), rng(seed), extent(extent_) {
    for (int i = 0; i < objects; ++i) add();
  }

  ObjectId add() {
    SceneObject o;
    o.model = models[rng() % models.size()];
    o.pose = random_pose(rng, extent);
    // Three groups; most objects meet every group, some only two of them.
    o.group = 1u << (rng() % 3);
    o.mask = rng() % 4 == 0 ? (7u & ~(1u << (rng() % 3))) : kAllGroups;
    if (rng() % 2) o.name = "obj" + std::to_string(rng());
    return scene.add(std::move(o));
  }

  void allow_some(int count) {
    const auto ids = scene.ids();
    for (int i = 0; i < count; ++i) {
      const ObjectId a = ids[rng() % ids.size()], b = ids[rng() % ids.size()];
      if (a != b) scene.allow(a, b);
    }
    // Allow some touching pairs too, so that the allowed set changes the answer.
    int allowed = 0;
    for (const ObjectPairHit& hit : collide(scene))
      if (allowed < 3 && rng() % 2) scene.allow(hit.a, hit.b), ++allowed;
  }

  void churn() {
    auto ids = scene.ids();
    for (int i = 0; i < 5 && !ids.empty(); ++i) {
      const std::size_t k = rng() % ids.size();
      scene.remove(ids[k]);
      ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(k));
    }
    for (int i = 0; i < 3; ++i) add();
    ids = scene.ids();
    scene.set_pose(ids[rng() % ids.size()], random_pose(rng, extent));
    std::vector<ObjectId> moved;
    std::vector<Pose> poses;
    for (int i = 0; i < 8; ++i) {
      moved.push_back(ids[rng() % ids.size()]);
      poses.push_back(random_pose(rng, extent));
    }
    scene.set_poses(moved, poses);
  }
};

void check_self_queries(const Scene& scene, const std::string& where) {
  for (const QueryMode mode : {QueryMode::first_hit, QueryMode::all_pairs}) {
    for (const double margin : {0.0, 0.05}) {
      const QueryOptions o{.mode = mode, .margin = margin};
      const std::string w = where + (mode == QueryMode::all_pairs ? " all_pairs" : " first_hit") +
                            " margin " + std::to_string(margin);
      const auto expected = brute_collide(scene, nullptr, o);
      expect_same(collide(scene, o), expected, w);
      expect_same(collide(scene, o, 2), expected, w + " 2 threads");
      expect_same(collide(scene, o, 0), expected, w + " all cores");
    }
  }
  for (const double d : {0.1, 0.4}) {
    const auto expected = brute_within(scene, nullptr, d, {});
    expect_same(distance_within(scene, d), expected, where + " within " + std::to_string(d));
    expect_same(distance_within(scene, d, {}, 2), expected, where + " within 2 threads");
  }
  const auto nearest = distance(scene);
  const auto expected = brute_nearest(scene, nullptr, {});
  ASSERT_EQ(nearest.has_value(), expected.has_value()) << where;
  if (nearest) {
    EXPECT_EQ(nearest->a, expected->a) << where;
    EXPECT_EQ(nearest->b, expected->b) << where;
    EXPECT_EQ(nearest->result.distance, expected->result.distance) << where;
    EXPECT_LT((nearest->result.point_a - nearest->result.point_b).norm(), nearest->result.distance + 1e-9) << where;
  }
}

TEST(Scene, SelfQueriesEqualBruteForceThroughChurn) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    RandomScene r(scene_test::mixed_models(), seed, 40, 3.5);
    r.allow_some(30);
    const std::string where = "seed " + std::to_string(seed);
    // The scene must have touching pairs for the comparison to mean something.
    EXPECT_GT(collide(r.scene).size(), 3u) << where;
    EXPECT_LT(collide(r.scene).size(), 200u) << where;
    check_self_queries(r.scene, where);
    for (int round = 0; round < 3; ++round) {
      r.churn();
      check_self_queries(r.scene, where + " churn " + std::to_string(round));
    }
  }
}

// The pair cache (scene.cpp): after a few objects move, the next query updates the cached pairs
// from the moved boxes alone; after many move, or with another margin, it walks the whole tree.
// Either way the answer must equal brute force, also when filters and allowed pairs change in
// between (they are applied after the cache).
TEST(Scene, PairCacheFollowsMovesFiltersAndMargins) {
  RandomScene r(scene_test::mixed_models(), 7, 60, 3.5);
  Scene& scene = r.scene;
  const QueryOptions o{.mode = QueryMode::all_pairs};
  expect_same(collide(scene, o), brute_collide(scene, nullptr, o), "initial");
  SceneTreeStats before = scene.tree_stats();
  for (int round = 0; round < 12; ++round) {
    const std::string where = "round " + std::to_string(round);
    auto ids = scene.ids();
    // Rounds 0-9 move 1 to 10 objects (at most a sixth of 60: an update); round 10 moves all
    // of them (a walk); round 11 moves none.
    const std::size_t count = round < 10 ? static_cast<std::size_t>(round + 1) : round == 10 ? ids.size() : 0;
    std::vector<ObjectId> moved;
    std::vector<Pose> poses;
    for (std::size_t k = 0; k < count; ++k) {
      moved.push_back(round == 10 ? ids[k] : ids[r.rng() % ids.size()]);
      Pose p = scene.object(moved.back()).pose;
      p.translation += Vec3(0.3, -0.2, 0.25) * (static_cast<double>(r.rng() % 4) - 1.5);  // never 0
      poses.push_back(p);
    }
    scene.set_poses(moved, poses);
    if (round == 4) scene.set_filter(ids[3], 1u, 0u);  // meets nothing
    if (round == 6) r.allow_some(4);
    expect_same(collide(scene, o), brute_collide(scene, nullptr, o), where);
    const SceneTreeStats after = scene.tree_stats();
    if (round < 10) {
      EXPECT_EQ(after.pair_walks, before.pair_walks) << where;
      EXPECT_GT(after.pair_updates, before.pair_updates) << where;
    } else if (round == 10) {
      EXPECT_EQ(after.pair_walks, before.pair_walks + 1) << where;
    } else {
      EXPECT_EQ(after.pair_walks, before.pair_walks) << where;
      EXPECT_EQ(after.pair_updates, before.pair_updates) << where;
    }
    before = after;
  }
  // Another margin walks the tree again, then the cache serves it.
  const QueryOptions wide{.mode = QueryMode::all_pairs, .margin = 0.05};
  expect_same(collide(scene, wide), brute_collide(scene, nullptr, wide), "margin 0.05");
  EXPECT_EQ(scene.tree_stats().pair_walks, before.pair_walks + 1);
  expect_same(collide(scene, wide), brute_collide(scene, nullptr, wide), "margin 0.05 again");
  EXPECT_EQ(scene.tree_stats().pair_walks, before.pair_walks + 1);
}

// A pose that leaves an object's world box as it was is no move for the broad phase: neither the
// tree nor the pair cache changes, and the answers stay brute force's; a real move after it
// updates the cache as before.
TEST(Scene, RePosingInPlaceKeepsTheBroadPhase) {
  RandomScene r(scene_test::mixed_models(), 11, 60, 3.5);
  Scene& scene = r.scene;
  const QueryOptions o{.mode = QueryMode::all_pairs};
  expect_same(collide(scene, o), brute_collide(scene, nullptr, o), "initial");
  const SceneTreeStats before = scene.tree_stats();
  const std::vector<ObjectId> ids = scene.ids();
  std::vector<Pose> poses;
  for (const ObjectId id : ids) poses.push_back(scene.object(id).pose);
  scene.set_poses(ids, poses);
  scene.set_pose(ids[5], poses[5]);
  expect_same(collide(scene, o), brute_collide(scene, nullptr, o), "in place");
  const SceneTreeStats same = scene.tree_stats();
  EXPECT_EQ(same.refits, before.refits);
  EXPECT_EQ(same.pair_walks, before.pair_walks);
  EXPECT_EQ(same.pair_updates, before.pair_updates);
  Pose p = poses[7];
  p.translation += Vec3(0.4, 0.0, -0.3);
  scene.set_pose(ids[7], p);
  expect_same(collide(scene, o), brute_collide(scene, nullptr, o), "one moved");
  const SceneTreeStats moved = scene.tree_stats();
  EXPECT_EQ(moved.refits, before.refits + 1);
  EXPECT_EQ(moved.pair_walks, before.pair_walks);
  EXPECT_EQ(moved.pair_updates, before.pair_updates + 1);
}

// Boundary cases the random scenes rarely make: unit boxes on a lattice touch their neighbours
// exactly (faces, edges, corners), and with a spacing of 1 + margin they are exactly `margin`
// apart. The top level must keep every such pair.
TEST(Scene, ExactContactsOnALattice) {
  const ModelPtr box = make_model(query_test::cube());
  for (const double margin : {0.0, 0.125}) {
    Scene scene;
    std::mt19937_64 rng(17);
    for (int x = 0; x < 4; ++x)
      for (int y = 0; y < 4; ++y)
        for (int z = 0; z < 3; ++z) {
          if (rng() % 5 == 0) continue;
          Pose p;
          p.translation = (1.0 + margin) * Vec3(x, y, z);
          if (rng() % 4 == 0) {  // a quarter turn about z is exact: the box stays where it was
            p.rotation << 0, -1, 0, 1, 0, 0, 0, 0, 1;
            p.translation.x() += 1.0;
          }
          scene.add(box, p);
        }
    const QueryOptions o{.mode = QueryMode::all_pairs, .margin = margin};
    const auto expected = brute_collide(scene, nullptr, o);
    EXPECT_GT(expected.size(), 50u);
    expect_same(collide(scene, o), expected, "lattice margin " + std::to_string(margin));
    const ObjectId last = scene.ids().back();
    Pose moved = scene.object(last).pose;
    moved.translation.z() += 1.0 + margin;  // on top of the lattice, touching exactly again
    const auto single = collide(scene, *box, moved, o);
    std::vector<ObjectId> expected_single;
    for (const ObjectId id : scene.ids()) {
      SceneObject q;
      q.model = box;
      q.pose = moved;
      if (pair_collide(scene.object(id), q, o).hit) expected_single.push_back(id);
    }
    ASSERT_EQ(single.size(), expected_single.size());
    EXPECT_GE(single.size(), 1u);
    for (std::size_t i = 0; i < single.size(); ++i) EXPECT_EQ(single[i].id, expected_single[i]);
  }
}

TEST(Scene, AllowedPairsAndFiltersAreNeverReported) {
  RandomScene r(scene_test::mixed_models(), 11, 40, 3.0);
  r.allow_some(50);
  for (const ObjectPairHit& hit : collide(r.scene)) {
    EXPECT_LT(hit.a, hit.b);
    EXPECT_FALSE(r.scene.allowed(hit.a, hit.b));
    EXPECT_TRUE(filters_meet(r.scene.object(hit.a), r.scene.object(hit.b)));
  }
  // Every object in a group no one's mask meets: nothing.
  for (const ObjectId id : r.scene.ids()) r.scene.set_filter(id, 8, 7);
  EXPECT_TRUE(collide(r.scene).empty());
  EXPECT_FALSE(distance(r.scene).has_value());
}

TEST(Scene, SolidSelfQueriesEqualBruteForce) {
  RandomScene r(scene_test::closed_models(), 5, 40, 3.0);
  // A small box inside a large one: only a containment, no touching triangles.
  const ModelPtr big = make_model(query_test::cube(Vec3::Constant(-1.0), 2.0));
  const ModelPtr small = make_model(query_test::cube(Vec3::Constant(-0.1), 0.2));
  Pose far;
  far.translation = Vec3(20, 20, 20);
  const ObjectId outer = r.scene.add(big, far);
  const ObjectId inner = r.scene.add(small, far);
  for (const double margin : {0.0, 0.02}) {
    const QueryOptions o{.margin = margin, .solid = true};
    const auto expected = brute_collide(r.scene, nullptr, o);
    expect_same(collide(r.scene, o), expected, "solid");
    bool contained = false;
    for (const ObjectPairHit& hit : expected) contained |= hit.a == outer && hit.b == inner;
    EXPECT_TRUE(contained);
  }
  const auto nearest = distance(r.scene, {.solid = true});
  ASSERT_TRUE(nearest.has_value());
  EXPECT_EQ(nearest->result.distance, 0.0);
  const auto expected = brute_nearest(r.scene, nullptr, {.solid = true});
  EXPECT_EQ(nearest->a, expected->a);
  EXPECT_EQ(nearest->b, expected->b);
}

TEST(Scene, SingleObjectQueriesAndBatchEqualBruteForce) {
  RandomScene r(scene_test::mixed_models(), 21, 50, 3.0);
  r.churn();
  const ModelPtr query = r.models[4];  // the knot
  std::vector<Pose> poses;
  for (int i = 0; i < 40; ++i) poses.push_back(random_pose(r.rng, 3.0));
  const QueryOptions all{.mode = QueryMode::all_pairs};
  int touching = 0;
  std::vector<std::vector<ObjectHit>> expected_batch;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    SceneObject q;
    q.model = query;
    q.pose = poses[p];
    std::vector<ObjectHit> expected;
    for (const ObjectId id : r.scene.ids()) {
      QueryResult res = pair_collide(r.scene.object(id), q, all);
      if (res.hit) expected.push_back({id, std::move(res)});
    }
    const auto got = collide(r.scene, *query, poses[p], all);
    ASSERT_EQ(got.size(), expected.size()) << "pose " << p;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].id, expected[i].id);
      expect_same(got[i].result, expected[i].result, "pose " + std::to_string(p));
    }
    touching += !expected.empty();
    // distance: nearest and within.
    std::optional<ObjectDistance> nearest_expected;
    std::vector<ObjectId> within_expected;
    for (const ObjectId id : r.scene.ids()) {
      const DistanceResult d = pair_distance(r.scene.object(id), q, {});
      if (!nearest_expected || d.distance < nearest_expected->result.distance) nearest_expected = ObjectDistance{id, d};
      if (d.distance < 0.2) within_expected.push_back(id);
    }
    const auto nearest = distance(r.scene, *query, poses[p]);
    ASSERT_TRUE(nearest.has_value());
    EXPECT_EQ(nearest->id, nearest_expected->id) << "pose " << p;
    EXPECT_EQ(nearest->result.distance, nearest_expected->result.distance) << "pose " << p;
    std::vector<ObjectId> within;
    for (const ObjectDistance& d : distance_within(r.scene, *query, poses[p], 0.2)) within.push_back(d.id);
    EXPECT_EQ(within, within_expected) << "pose " << p;
    expected_batch.push_back(std::move(expected));
  }
  EXPECT_GT(touching, 5);
  EXPECT_LT(touching, 40);
  for (const unsigned threads : {1u, 2u, 0u}) {
    const auto batch = collide_batch(r.scene, *query, poses, all, threads);
    ASSERT_EQ(batch.size(), poses.size());
    for (std::size_t p = 0; p < poses.size(); ++p) {
      ASSERT_EQ(batch[p].size(), expected_batch[p].size()) << "pose " << p << " threads " << threads;
      for (std::size_t i = 0; i < batch[p].size(); ++i) {
        EXPECT_EQ(batch[p][i].id, expected_batch[p][i].id);
        expect_same(batch[p][i].result, expected_batch[p][i].result, "batch pose " + std::to_string(p));
      }
    }
  }
  std::vector<Pose> bad = poses;
  bad[7].translation.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)collide_batch(r.scene, *query, bad);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pose 7"), std::string::npos) << e.what();
  }
}

TEST(Scene, SceneAgainstSceneEqualsBruteForce) {
  RandomScene robot(scene_test::mixed_models(), 31, 15, 3.0);
  RandomScene cell(scene_test::mixed_models(), 32, 40, 3.0);
  cell.churn();
  robot.churn();
  for (const double margin : {0.0, 0.03}) {
    const QueryOptions o{.mode = QueryMode::all_pairs, .margin = margin};
    const auto expected = brute_collide(robot.scene, &cell.scene, o);
    EXPECT_GT(expected.size(), 2u);
    expect_same(collide(robot.scene, cell.scene, o), expected, "cross");
    expect_same(collide(robot.scene, cell.scene, o, 2), expected, "cross 2 threads");
  }
  expect_same(distance_within(robot.scene, cell.scene, 0.3), brute_within(robot.scene, &cell.scene, 0.3, {}),
              "cross within");
  const auto nearest = distance(robot.scene, cell.scene);
  const auto expected = brute_nearest(robot.scene, &cell.scene, {});
  ASSERT_TRUE(nearest.has_value());
  EXPECT_EQ(nearest->a, expected->a);
  EXPECT_EQ(nearest->b, expected->b);
  EXPECT_EQ(nearest->result.distance, expected->result.distance);
  EXPECT_THROW((void)collide(robot.scene, robot.scene), InputError);
}

TEST(Scene, NearestOfSeparatedObjectsWithUpperBound) {
  // A row of unit boxes 1 apart, the last gap smaller: the nearest pair is the last one.
  const ModelPtr box = make_model(query_test::cube());
  Scene scene;
  std::vector<ObjectId> ids;
  for (int i = 0; i < 10; ++i) {
    Pose p;
    p.translation = Vec3(2.0 * i - (i == 9 ? 0.5 : 0.0), 0, 0);
    ids.push_back(scene.add(box, p));
  }
  const auto nearest = distance(scene);
  ASSERT_TRUE(nearest.has_value());
  EXPECT_EQ(nearest->a, ids[8]);
  EXPECT_EQ(nearest->b, ids[9]);
  EXPECT_DOUBLE_EQ(nearest->result.distance, 0.5);
  EXPECT_FALSE(distance(scene, {.upper_bound = 0.5}).has_value());
  EXPECT_EQ(distance_within(scene, 0.6).size(), 1u);
  EXPECT_EQ(distance_within(scene, 1.0 + 1e-9).size(), 9u);
  EXPECT_TRUE(collide(scene).empty());
  EXPECT_EQ(collide(scene, {.margin = 0.5}).size(), 1u);
}

TEST(Scene, BadInputIsAnInputErrorNamingWhat) {
  const ModelPtr box = make_model(query_test::cube());
  Scene scene;
  const ObjectId a = scene.add(box, Pose{}, "a");
  const auto message = [](auto&& fn) -> std::string {
    try {
      fn();
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(message([&] { scene.add(nullptr, Pose{}); }).find("null"), std::string::npos);
  EXPECT_NE(message([&] { scene.add(box, Pose{}, "a"); }).find("duplicate name 'a'"), std::string::npos);
  Pose nan;
  nan.rotation(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message([&] { scene.add(box, nan); }).find("not finite"), std::string::npos);
  Pose skew;
  skew.rotation(0, 1) = 1e-3;
  EXPECT_NE(message([&] { scene.set_pose(a, skew); }).find("not orthonormal"), std::string::npos);
  Pose mirror;
  mirror.rotation(2, 2) = -1.0;
  EXPECT_NE(message([&] { scene.set_pose(a, mirror); }).find("reflection"), std::string::npos);
  EXPECT_NE(message([&] { scene.set_pose(99, Pose{}); }).find("no object with id 99"), std::string::npos);
  scene.remove(a);
  EXPECT_NE(message([&] { scene.remove(a); }).find("was removed"), std::string::npos);
  EXPECT_NE(message([&] { (void)scene.object(a); }).find("no object with id 0"), std::string::npos);
  // The name is free again; ids are not reused.
  const ObjectId again = scene.add(box, Pose{}, "a");
  EXPECT_NE(again, a);
  EXPECT_EQ(scene.find("a"), again);
  // set_poses checks every entry before moving any.
  const ObjectId b = scene.add(box, Pose{});
  Pose moved;
  moved.translation = Vec3(5, 0, 0);
  const std::vector<ObjectId> ids{b, again};
  EXPECT_NE(message([&] { scene.set_poses(ids, std::vector<Pose>{moved, skew}); }).find("entry 1"), std::string::npos);
  EXPECT_EQ(scene.object(b).pose.translation, Vec3::Zero());
  EXPECT_NE(message([&] { scene.set_poses(ids, std::vector<Pose>{moved}); }).find("2 ids but 1 poses"),
            std::string::npos);
  EXPECT_NE(message([&] { (void)collide(scene, {.margin = -1.0}); }).find("margin"), std::string::npos);
  EXPECT_NE(message([&] { (void)collide(scene, *box, nan); }).find("not finite"), std::string::npos);
}

TEST(Scene, TenThousandObjectsSharingTenModelsHoldTenTrees) {
  std::vector<ModelPtr> models;
  std::size_t bytes = 0;
  for (int i = 0; i < 10; ++i) {
    models.push_back(make_model(query_test::uv_sphere(4 + i, 6 + i, 0.5)));
    bytes += models.back()->bytes();
  }
  Scene scene;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 10'000; ++i) scene.add(models[i % 10], random_pose(rng, 60.0));
  EXPECT_EQ(scene.model_count(), 10u);
  EXPECT_EQ(scene.model_bytes(), bytes);
  for (const ModelPtr& m : models) EXPECT_EQ(m.use_count(), 1 + 1000);
  // The scene's own data is per object, far less than a tree per object would take.
  EXPECT_LT(scene.own_bytes(), 10'000 * models[0]->bytes());
  const SceneTreeStats stats = scene.tree_stats();
  EXPECT_EQ(stats.objects, 10'000u);
  EXPECT_EQ(stats.nodes, 19'999u);
  // A copy shares the models.
  const Scene copy = scene;
  EXPECT_EQ(models[0].use_count(), 1 + 2000);
  EXPECT_EQ(copy.size(), scene.size());
}

TEST(Scene, TopTreeRefitsOnMovesAndRebuildsOnChanges) {
  const ModelPtr box = make_model(query_test::cube());
  Scene scene;
  std::mt19937_64 rng(9);
  std::vector<ObjectId> ids;
  for (int i = 0; i < 100; ++i) ids.push_back(scene.add(box, random_pose(rng, 20.0)));
  SceneTreeStats s = scene.tree_stats();
  EXPECT_EQ(s.rebuilds, 1u);
  EXPECT_EQ(s.refits, 0u);
  scene.set_pose(ids[3], random_pose(rng, 20.0));
  (void)collide(scene);
  s = scene.tree_stats();
  EXPECT_EQ(s.refits, 1u);
  scene.remove(ids[4]);
  s = scene.tree_stats();
  EXPECT_GE(s.rebuilds, 2u);
  EXPECT_EQ(s.nodes, 2 * 99u - 1);
  // Every object moved far: the refit tree is much looser than a fresh one, so it is rebuilt.
  const std::uint64_t before = s.rebuilds;
  for (const ObjectId id : scene.ids()) scene.set_pose(id, random_pose(rng, 20.0));
  s = scene.tree_stats();
  EXPECT_EQ(s.rebuilds, before + 1);
  EXPECT_LE(s.cost, 2.0 * s.built_cost);
}

TEST(Scene, EmptyAndSingleObjectScenes) {
  Scene scene;
  const ModelPtr box = make_model(query_test::cube());
  EXPECT_TRUE(collide(scene).empty());
  EXPECT_FALSE(distance(scene).has_value());
  EXPECT_TRUE(collide(scene, *box, Pose{}).empty());
  EXPECT_FALSE(distance(scene, *box, Pose{}).has_value());
  EXPECT_TRUE(collide_batch(scene, *box, std::vector<Pose>(3)).at(2).empty());
  const ObjectId id = scene.add(box, Pose{});
  EXPECT_TRUE(collide(scene).empty());
  EXPECT_FALSE(distance(scene).has_value());
  const auto hits = collide(scene, *box, Pose{});
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].id, id);
}

// is_valid_pose (the queries' check without a message) accepts exactly what require_valid_pose
// accepts: exact and perturbed rotations around the tolerance, reflections, every entry NaN or
// infinite in turn, and entries large enough for the Gram products to overflow.
TEST(Scene, IsValidPoseAgreesWithRequireValidPose) {
  const auto accepted = [](const Pose& p) {
    try {
      require_valid_pose(p, "test", "pose");
      return true;
    } catch (const InputError&) {
      return false;
    }
  };
  std::vector<Pose> poses;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 200; ++i) {
    Pose p;
    p.rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
    p.translation = Vec3(normal(rng), normal(rng), normal(rng)) * 1e3;
    poses.push_back(p);
    for (const double scale : {1e-7, 4e-7, 6e-7, 1e-6, 2e-6, 1e-3}) {  // around kRotationTolerance
      Pose q = p;
      q.rotation(i % 3, (i / 3) % 3) += scale;
      poses.push_back(q);
      q.rotation.col(i % 3) *= 1.0 + scale;
      poses.push_back(q);
    }
    Pose reflected = p;
    reflected.rotation.col(i % 3) *= -1.0;
    poses.push_back(reflected);
  }
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(), 1e200, -1e160};
  for (const double x : specials)
    for (int k = 0; k < 12; ++k) {
      Pose p = poses[static_cast<std::size_t>(k)];
      (k < 9 ? p.rotation.data()[k] : p.translation[k - 9]) = x;
      poses.push_back(p);
    }
  int rejected = 0;
  for (const Pose& p : poses) {
    EXPECT_EQ(is_valid_pose(p), accepted(p)) << "rotation\n" << p.rotation << "\ntranslation " << p.translation.transpose();
    rejected += !accepted(p);
  }
  EXPECT_GT(rejected, 1000);  // both verdicts occur
  EXPECT_LT(rejected, static_cast<int>(poses.size()) - 500);
}

}  // namespace
}  // namespace tightbvh
