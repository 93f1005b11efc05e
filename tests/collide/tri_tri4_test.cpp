// all_pairs' four-lane triangle test (src/collide/tri_tri4.hpp): every lane it decides must answer
// as the exact tri_tri_overlap() on the same doubles, on random crossing and separated pairs, on
// pairs within rounding of touching (shared corners and edges, a corner on the other's plane,
// coplanar, degenerate, NaN) and on the shipped meshes' triangle pairs under random poses; and it
// must decide the plain ones, so that the lanes, not the scalar fallback, carry the test.
#include "collide/tri_tri4.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "query_fixtures.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/tri_tri.hpp"

namespace tightbvh {
namespace {

using query_test::shipped;
using Tri = std::array<Vec3, 3>;
struct Pair {
  Tri p, q;
};

struct Tally {
  int pairs = 0, decided = 0, decided_touching = 0, undecided = 0;
};

// Runs the pairs through the lanes four at a time; every decided lane must equal the exact test.
Tally check_lanes(const std::vector<Pair>& pairs) {
  Tally tally;
  for (std::size_t first = 0; first < pairs.size(); first += 4) {
    query_detail::TriPairs4 lanes;
    for (int lane = 0; lane < 4; ++lane) {
      const Pair& pair = pairs[std::min(first + lane, pairs.size() - 1)];
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) {
          lanes.c[3 * k + i][lane] = pair.p[k][i];
          lanes.c[9 + 3 * k + i][lane] = pair.q[k][i];
        }
    }
#ifdef TIGHTBVH_AVX2_BOUNDS
    const int answer = query_detail::tri_tri_overlap4_avx2(lanes);
#else
    const int answer = 0;  // not built here: the fixture skips
#endif
    for (int lane = 0; lane < 4 && first + lane < pairs.size(); ++lane) {
      const Pair& pair = pairs[first + lane];
      ++tally.pairs;
      if ((answer >> lane & 1) == 0) {
        ++tally.undecided;
        continue;
      }
      ++tally.decided;
      const bool lanes_touch = (answer >> (4 + lane) & 1) != 0;
      tally.decided_touching += lanes_touch ? 1 : 0;
      EXPECT_EQ(lanes_touch, tri_tri_overlap(pair.p, pair.q))
          << "pair " << first + lane << ": p " << pair.p[0].transpose() << " | " << pair.p[1].transpose() << " | "
          << pair.p[2].transpose() << "; q " << pair.q[0].transpose() << " | " << pair.q[1].transpose() << " | "
          << pair.q[2].transpose();
    }
  }
  return tally;
}

Vec3 random_point(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

Tri random_triangle(std::mt19937_64& rng, const Vec3& center, double size) {
  return {center + random_point(rng, size), center + random_point(rng, size), center + random_point(rng, size)};
}

class TriTri4 : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!query_detail::avx2_bounds_available()) GTEST_SKIP() << "no AVX2 on this CPU: collide() uses the scalar test";
  }
};

TEST_F(TriTri4, RandomPairsDecideAsTheExactTest) {
  std::mt19937_64 rng(7);
  std::vector<Pair> pairs;
  for (int i = 0; i < 40000; ++i) {
    // Triangles of size 1 with centers up to 1.5 apart: about as many touch as not. Every fourth
    // pair far from the origin, where the differences round.
    const Vec3 offset = i % 4 == 3 ? Vec3(1e6, -3e5, 2e7) : Vec3::Zero();
    pairs.push_back({random_triangle(rng, offset, 1.0), random_triangle(rng, offset + random_point(rng, 0.75), 1.0)});
  }
  const Tally tally = check_lanes(pairs);
  // The lanes carry the test: nearly every such pair is decided, touching ones included.
  EXPECT_GE(tally.decided, tally.pairs * 99 / 100);
  EXPECT_GE(tally.decided_touching, tally.pairs / 10);
  EXPECT_LE(tally.decided_touching, tally.pairs * 9 / 10);
}

TEST_F(TriTri4, PairsWithinRoundingOfTouchingAreLeftToTheExactTest) {
  std::mt19937_64 rng(11);
  std::vector<Pair> pairs;
  for (int i = 0; i < 4000; ++i) {
    const Tri p = random_triangle(rng, Vec3::Zero(), 1.0);
    Tri q = random_triangle(rng, Vec3::Zero(), 1.0);
    switch (i % 8) {
      case 0: q[0] = p[1]; break;                        // a shared corner
      case 1: q[0] = p[0], q[1] = p[2]; break;           // a shared edge
      case 2: q[2] = (p[0] + p[1]) * 0.5; break;         // a corner on an edge (rounded)
      case 3: q[1] = p[0] + 0.3 * (p[1] - p[0]) + 0.2 * (p[2] - p[0]); break;  // a corner on the face
      case 4: {                                          // coplanar: q in p's plane
        for (Vec3& v : q) {
          std::uniform_real_distribution<double> u(-0.5, 1.5);
          v = p[0] + u(rng) * (p[1] - p[0]) + u(rng) * (p[2] - p[0]);
        }
        break;
      }
      case 5: q[2] = q[0] + 2.0 * (q[1] - q[0]); break;  // q degenerate: collinear corners
      case 6: q = {p[0], p[0], p[0]}; break;             // q a point, p's corner
      default: q[1].y() = std::numeric_limits<double>::quiet_NaN(); break;
    }
    pairs.push_back({p, q});
    pairs.push_back({q, p});
  }
  const Tally tally = check_lanes(pairs);
  EXPECT_GT(tally.undecided, tally.pairs / 4);  // the exact test gets the ties
  EXPECT_GT(tally.decided, 0);                  // while strict corners elsewhere still decide
}

TEST_F(TriTri4, ShippedMeshPairsDecideAsTheExactTest) {
  const Mesh a = shipped("meshes/elephant.off");
  const Mesh b = shipped("meshes/knot1.off");
  std::mt19937_64 rng(3);
  std::vector<Pair> pairs;
  std::uniform_int_distribution<std::uint32_t> pick_a(0, static_cast<std::uint32_t>(a.triangles.size() - 1));
  std::uniform_int_distribution<std::uint32_t> pick_b(0, static_cast<std::uint32_t>(b.triangles.size() - 1));
  const auto centroid = [](const std::array<Vec3, 3>& t) { return Vec3((t[0] + t[1] + t[2]) / 3.0); };
  for (int pose = 0; pose < 16; ++pose) {
    // A random triangle of B moved onto a random triangle of A, turned at random: the surfaces
    // cross there. Every pair of the triangles around that point whose bounding boxes overlap
    // (the pairs that reach a leaf test).
    std::normal_distribution<double> n;
    const Mat3 r = Eigen::Quaterniond(Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
    const Vec3 at = centroid(a.corners(pick_a(rng)));
    const Vec3 t = at - r * centroid(b.corners(pick_b(rng)));
    std::vector<Tri> near_a, near_b;
    for (std::uint32_t i = 0; i < a.triangles.size(); ++i)
      if (const Tri p = a.corners(i); (centroid(p) - at).norm() < 0.04) near_a.push_back(p);
    for (std::uint32_t i = 0; i < b.triangles.size(); ++i) {
      const auto [q0, q1, q2] = b.corners(i);
      if (const Tri q = {r * q0 + t, r * q1 + t, r * q2 + t}; (centroid(q) - at).norm() < 0.04) near_b.push_back(q);
    }
    for (const Tri& p : near_a)
      for (const Tri& q : near_b) {
        const Vec3 p_lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]), p_hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
        const Vec3 q_lo = q[0].cwiseMin(q[1]).cwiseMin(q[2]), q_hi = q[0].cwiseMax(q[1]).cwiseMax(q[2]);
        if ((p_lo.array() <= q_hi.array()).all() && (q_lo.array() <= p_hi.array()).all()) pairs.push_back({p, q});
      }
  }
  const Tally tally = check_lanes(pairs);
  EXPECT_GE(tally.pairs, 1000);
  EXPECT_GE(tally.decided, tally.pairs * 99 / 100);
  EXPECT_GT(tally.decided_touching, 0);
}

}  // namespace
}  // namespace tightbvh
