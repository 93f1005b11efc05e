// The exact orientation predicates of src/collide (internal header), checked against 128-bit
// integer arithmetic on nearly (and exactly) coplanar / collinear grid points. The exact
// expansion path is also called directly on coordinates offset by 2^45, where the products it
// sums are ~2^135 and cancel down to the small determinant.
#include "geometry/predicates.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tightbvh/aabb.hpp"

namespace tightbvh::detail {
namespace {

using I128 = __int128;

int sign128(I128 x) { return (x > 0) - (x < 0); }

TEST(Predicates, Orient3dExactOnNearlyCoplanarGridPoints) {
  std::mt19937_64 rng(17);
  std::uniform_int_distribution<std::int64_t> coord(-(1 << 20), 1 << 20);
  std::uniform_real_distribution<double> weight(-2.0, 2.0);
  std::uniform_int_distribution<int> nudge(-1, 1);
  const double scale = std::ldexp(1.0, -30);  // k * 2^-30 is exact in double
  int signs[3] = {0, 0, 0};
  for (int iter = 0; iter < 100000; ++iter) {
    std::int64_t p[4][3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) p[i][k] = coord(rng);
    const bool exact_plane = iter % 3 == 0;  // integer weights, no nudge: exactly coplanar
    const double s = exact_plane ? std::round(weight(rng)) : weight(rng);
    const double t = exact_plane ? std::round(weight(rng)) : weight(rng);
    for (int k = 0; k < 3; ++k)
      p[3][k] = static_cast<std::int64_t>(std::llround(p[0][k] + s * (p[1][k] - p[0][k]) + t * (p[2][k] - p[0][k]))) +
                (exact_plane ? 0 : nudge(rng));
    I128 u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k], w[k] = p[3][k] - p[0][k];
    const I128 det = w[0] * (u[1] * v[2] - u[2] * v[1]) + w[1] * (u[2] * v[0] - u[0] * v[2]) +
                     w[2] * (u[0] * v[1] - u[1] * v[0]);
    Vec3 q[4];
    for (int i = 0; i < 4; ++i) q[i] = Vec3(p[i][0] * scale, p[i][1] * scale, p[i][2] * scale);
    ASSERT_EQ(orient3d(q[0], q[1], q[2], q[3]), sign128(det)) << "iteration " << iter;
    ASSERT_EQ(orient3d_exact(q[0], q[1], q[2], q[3]), sign128(det)) << "iteration " << iter;
    const Vec3 offset = Vec3::Constant(std::ldexp(1.0, 45));
    Vec3 far[4];
    for (int i = 0; i < 4; ++i) far[i] = offset + Vec3(double(p[i][0]), double(p[i][1]), double(p[i][2]));
    ASSERT_EQ(orient3d_exact(far[0], far[1], far[2], far[3]), sign128(det)) << "iteration " << iter;
    ASSERT_EQ(orient3d(far[0], far[1], far[2], far[3]), sign128(det)) << "iteration " << iter;
    ++signs[sign128(det) + 1];
  }
  EXPECT_GT(signs[0], 1000);
  EXPECT_GT(signs[1], 1000);
  EXPECT_GT(signs[2], 1000);
}

TEST(Predicates, Orient2dExactOnNearlyCollinearPoints) {
  std::mt19937_64 rng(19);
  std::uniform_int_distribution<std::int64_t> coord(-(1 << 26), 1 << 26);
  std::uniform_real_distribution<double> weight(-2.0, 2.0);
  std::uniform_int_distribution<int> nudge(-1, 1);
  int signs[3] = {0, 0, 0};
  for (int iter = 0; iter < 100000; ++iter) {
    std::int64_t a[2], b[2], c[2];
    for (int k = 0; k < 2; ++k) a[k] = coord(rng), b[k] = coord(rng);
    const bool exact_line = iter % 3 == 0;
    const double s = exact_line ? std::round(weight(rng)) : weight(rng);
    for (int k = 0; k < 2; ++k) c[k] = std::llround(a[k] + s * (b[k] - a[k])) + (exact_line ? 0 : nudge(rng));
    const I128 det = I128(b[0] - a[0]) * (c[1] - a[1]) - I128(b[1] - a[1]) * (c[0] - a[0]);
    const double f = std::ldexp(1.0, -40);
    ASSERT_EQ(orient2d(a[0] * f, a[1] * f, b[0] * f, b[1] * f, c[0] * f, c[1] * f), sign128(det));
    ASSERT_EQ(orient2d_exact(a[0] * f, a[1] * f, b[0] * f, b[1] * f, c[0] * f, c[1] * f), sign128(det));
    const double o = std::ldexp(1.0, 45);
    ASSERT_EQ(orient2d_exact(o + a[0], o + a[1], o + b[0], o + b[1], o + c[0], o + c[1]), sign128(det));
    ++signs[sign128(det) + 1];
  }
  EXPECT_GT(signs[0], 1000);
  EXPECT_GT(signs[1], 1000);
  EXPECT_GT(signs[2], 1000);
}

// Nearly coplanar points with coordinates of mixed magnitudes: the differences are not exact
// doubles, so the general expansion path (24 products of three coordinates) decides. Reference:
// the determinant in binary128 (113-bit significand: differences of these doubles are exact, and
// the products' rounding is ~2^-110 of the permanent, far below the determinants here), compared
// only where it is decisive.
TEST(Predicates, Orient3dGeneralPathAgainstQuadPrecision) {
  using Q = __float128;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-8, 8);
  int compared = 0, signs[3] = {0, 0, 0};
  for (int iter = 0; iter < 20000; ++iter) {
    const auto coord = [&] { return std::ldexp(u(rng), exponent(rng)); };
    const Vec3 a(coord(), coord(), coord()), b(coord(), coord(), coord()), c(coord(), coord(), coord());
    const double s = u(rng), t = u(rng);
    const Vec3 d = a + s * (b - a) + t * (c - a);  // on the plane up to rounding
    Q uq[3], vq[3], wq[3];
    for (int k = 0; k < 3; ++k) uq[k] = Q(b[k]) - Q(a[k]), vq[k] = Q(c[k]) - Q(a[k]), wq[k] = Q(d[k]) - Q(a[k]);
    const Q det = wq[0] * (uq[1] * vq[2] - uq[2] * vq[1]) + wq[1] * (uq[2] * vq[0] - uq[0] * vq[2]) +
                  wq[2] * (uq[0] * vq[1] - uq[1] * vq[0]);
    const auto qabs = [](Q x) { return x < 0 ? -x : x; };
    const Q permanent = qabs(wq[0]) * (qabs(uq[1] * vq[2]) + qabs(uq[2] * vq[1])) +
                        qabs(wq[1]) * (qabs(uq[2] * vq[0]) + qabs(uq[0] * vq[2])) +
                        qabs(wq[2]) * (qabs(uq[0] * vq[1]) + qabs(uq[1] * vq[0]));
    if (qabs(det) <= permanent * Q(std::ldexp(1.0, -100))) continue;
    const int expected = det > 0 ? 1 : -1;
    ASSERT_EQ(orient3d_exact(a, b, c, d), expected) << "iteration " << iter;
    ASSERT_EQ(orient3d(a, b, c, d), expected) << "iteration " << iter;
    // Corner permutations: an even one keeps the sign, an odd one flips it.
    ASSERT_EQ(orient3d_exact(b, c, a, d), expected) << "iteration " << iter;
    ASSERT_EQ(orient3d_exact(b, a, c, d), -expected) << "iteration " << iter;
    ++compared;
    ++signs[expected + 1];
  }
  EXPECT_GT(compared, 15000);
  EXPECT_GT(signs[0], 3000);
  EXPECT_GT(signs[2], 3000);
}

// Points on lines parallel to an axis (an extruded shape). With two corners on such a line,
// d on that line is decided through a rotated base point (every product then has a zero factor)
// and d on the parallel line through the third corner (the plane holds the axis direction)
// through a 2D orientation in the other two coordinates; both without orient3d's exact stages.
// d moved off by one ulp must keep its exact sign (reference: orient3d_exact).
TEST(Predicates, OrientPlaneOnAxisParallelLines) {
  std::mt19937_64 rng(29);
  std::uniform_int_distribution<std::int64_t> coord(-1000, 1000);
  std::uniform_int_distribution<int> axis(0, 2);
  int zeros = 0, undecided = 0;
  for (int iter = 0; iter < 60000; ++iter) {
    Vec3 q[4];
    for (int i = 0; i < 3; ++i) q[i] = Vec3(double(coord(rng)), double(coord(rng)), double(coord(rng))) * 0.1;
    const int line = axis(rng), first = iter % 3, second = (first + 1) % 3, third = (first + 2) % 3;
    q[second] = q[first];
    q[second][line] += 0.1 * double(50 + std::abs(coord(rng)) % 50);
    q[3] = (iter / 3) % 2 ? q[first] : q[third];
    q[3][line] = 0.1 * double(coord(rng));
    const int off = (line + 1 + iter % 2) % 3;
    if (iter % 4 == 1) q[3][off] = std::nextafter(q[3][off], 1e9);
    if (iter % 4 == 2) q[3][off] = std::nextafter(q[3][off], -1e9);
    const OrientPlane plane(q[0], q[1], q[2]);
    double det;
    undecided += plane.filter(q[3], det) == kUndecided;
    const int expected = orient3d_exact(q[0], q[1], q[2], q[3]);
    zeros += expected == 0;
    ASSERT_EQ(plane.sign(q[3]), expected) << "iteration " << iter;
  }
  EXPECT_GT(zeros, 20000);
  EXPECT_GT(undecided, 10000);
}

// bound_within / classify_within: a sign decided against the bound for a box holding all the
// points agrees with the exact sign, also for nearly coplanar points.
TEST(Predicates, OrientPlaneBoundWithinABox) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int decided = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    const Vec3 offset = Vec3(u(rng), u(rng), u(rng)) * (iter % 2 ? 1e6 : 1.0);
    const Vec3 a = offset + Vec3(u(rng), u(rng), u(rng)), b = offset + Vec3(u(rng), u(rng), u(rng)),
               c = offset + Vec3(u(rng), u(rng), u(rng));
    const double s = u(rng), t = u(rng);
    const Vec3 d = iter % 4 == 0 ? Vec3(offset + Vec3(u(rng), u(rng), u(rng))) : Vec3(a + s * (b - a) + t * (c - a));
    Aabb box;
    for (const Vec3& p : {a, b, c, d}) box.extend(p);
    const OrientPlane plane(a, b, c);
    double det;
    bool above, below;
    plane.classify_within(d, plane.bound_within(box.extents()), det, above, below);
    ASSERT_FALSE(above && below);
    const int exact = orient3d_exact(a, b, c, d);
    if (above) ASSERT_EQ(exact, 1) << "iteration " << iter;
    if (below) ASSERT_EQ(exact, -1) << "iteration " << iter;
    decided += above || below;
  }
  EXPECT_GT(decided, 5000);
}

// Classic case where the rounded determinant has the wrong sign: points on a line through
// non-representable values, one perturbed by one ulp.
TEST(Predicates, Orient2dBeatsRounding) {
  const double x = 0.5 + std::ldexp(1.0, -52);
  // (12, 12), (24, 24) and (x, x + ulp): exactly one ulp above the diagonal.
  EXPECT_EQ(orient2d(12, 12, 24, 24, x, std::nextafter(x, 1.0)), 1);
  EXPECT_EQ(orient2d(12, 12, 24, 24, x, x), 0);
  EXPECT_EQ(orient2d(12, 12, 24, 24, x, std::nextafter(x, 0.0)), -1);
}

}  // namespace
}  // namespace tightbvh::detail
