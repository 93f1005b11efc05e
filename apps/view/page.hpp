#pragma once
// Writes a view page: apps/view/page.html with the scene (scene.hpp) and three.js inlined, one
// self-contained file with no network access (three.js is embedded in the binary at build time).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace tightbvh::view {

// The page's HTML text.
[[nodiscard]] std::string render_page(const nlohmann::json& scene);

// Writes dir/index.html (creating dir) and returns its path; throws InputError when it cannot.
std::filesystem::path write_page(const std::filesystem::path& dir, const nlohmann::json& scene);

}  // namespace tightbvh::view
