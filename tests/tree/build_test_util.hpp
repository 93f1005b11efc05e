#pragma once
// Shared helpers of the builder tests: which fitters exist yet, meshes, random soups.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tightbvh/build.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::test {

inline constexpr FitMethod kAllMethods[] = {FitMethod::aabb,   FitMethod::pca,         FitMethod::pca_vertex,
                                            FitMethod::diameter, FitMethod::approx, FitMethod::approx_snap,
                                            FitMethod::exact,  FitMethod::eberly2015, FitMethod::approx_kernel, FitMethod::normal_bopt, FitMethod::dito};

// The fitters land one by one (fit branch): a method is available when it fits a tetrahedron.
inline bool available(FitMethod method) {
  const std::vector<Vec3> corners{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  try {
    FitOptions options;
    options.method = method;
    (void)fit_triangles(corners, options);
    return true;
  } catch (const std::logic_error&) {
    return false;
  }
}

inline bool available(const Fitter& fitter) {
  if (const auto* m = std::get_if<FitMethod>(&fitter)) return available(*m);
  const auto& a = std::get<AutoFit>(fitter);
  return available(a.tight) && available(a.medium) && available(a.cheap);
}

// Every fitter the builder accepts: each FitMethod, then auto.
inline std::vector<Fitter> all_fitters() {
  std::vector<Fitter> out(std::begin(kAllMethods), std::end(kAllMethods));
  out.emplace_back(AutoFit{});
  return out;
}

// The first `max_triangles` triangles (a soup: unused vertices are fine).
inline Mesh first_triangles(Mesh mesh, std::size_t max_triangles) {
  if (mesh.triangles.size() > max_triangles) mesh.triangles.resize(max_triangles);
  return mesh;
}

// Heavier fitters get a subset so the suite stays fast (they are exercised at the root of
// the subset, where their input is largest).
inline std::size_t triangle_budget(const Fitter& fitter) {
  if (const auto* m = std::get_if<FitMethod>(&fitter)) {
    switch (*m) {
      case FitMethod::aabb:
      case FitMethod::pca:
      case FitMethod::pca_vertex:
        return 1u << 30;
      case FitMethod::exact:
      case FitMethod::eberly2015:
      case FitMethod::approx_snap:  // ~20 s for 318 triangles (dragknob), hence tiny subsets
        return 24;
      default:
        return 400;  // diameter, approx: hull + grid search at every node
    }
  }
  return 1500;  // auto: approx-kernel above 64 triangles, approx above 2048
}

inline bool is_cheap(const Fitter& fitter) { return triangle_budget(fitter) > 1500; }

inline std::filesystem::path source_dir() { return TIGHTBVH_SOURCE_DIR; }
inline std::filesystem::path binary_dir() { return TIGHTBVH_BINARY_DIR; }

// Random soup in a unit box, with the requested share of degenerate triangles (zero area:
// repeated vertex or collinear corners) and of duplicated triangles.
inline Mesh random_soup(std::size_t triangles, std::uint64_t seed, double degenerate = 0.0, double duplicated = 0.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> small(-0.05, 0.05);
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  Mesh mesh;
  for (std::size_t t = 0; t < triangles; ++t) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    if (t > 0 && coin(rng) < duplicated) {
      std::uniform_int_distribution<std::size_t> pick(0, mesh.triangles.size() - 1);
      mesh.triangles.push_back(mesh.triangles[pick(rng)]);
      continue;
    }
    const Vec3 a(u(rng), u(rng), u(rng));
    const Vec3 b = a + Vec3(small(rng), small(rng), small(rng));
    const Vec3 c = a + Vec3(small(rng), small(rng), small(rng));
    if (coin(rng) < degenerate) {
      if (coin(rng) < 0.5) {
        mesh.vertices.insert(mesh.vertices.end(), {a, b});
        mesh.triangles.push_back({base, base + 1, base + 1});  // repeated vertex
      } else {
        mesh.vertices.insert(mesh.vertices.end(), {a, b, 0.5 * (a + b)});  // collinear
        mesh.triangles.push_back({base, base + 1, base + 2});
      }
      continue;
    }
    mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  return mesh;
}

}  // namespace tightbvh::test
