#pragma once
// Part of tightbvh-fit-vs-cgal: a corpus mesh's vertices, or a printed "skipped" line (the corpus
// holds a few files our loader rejects, with the reason).
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <vector>

#include "tightbvh/mesh.hpp"

namespace tightbvh::fit_bench {

[[nodiscard]] inline std::optional<std::vector<Vec3>> vertices_or_skip(const std::filesystem::path& file) {
  try {
    return load_mesh(file).vertices;
  } catch (const std::exception& e) {
    std::printf("%-34s skipped: %s\n", file.filename().c_str(), e.what());
    return std::nullopt;
  }
}

}  // namespace tightbvh::fit_bench
