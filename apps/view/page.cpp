#include "view/page.hpp"

#include <fstream>
#include <system_error>

#include "tightbvh/error.hpp"
#include "view/embedded.hpp"

namespace tightbvh::view {
namespace {

// Inside a <script> element "</script" ends it early and "<!--" changes how the parser looks for
// the end. In JSON '<' only occurs in strings, where "\u003c" means the same.
std::string json_for_script(const nlohmann::json& scene) {
  // Invalid UTF-8 (a file name) is replaced, not thrown about.
  const std::string text = scene.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

// three.js has neither sequence (embed.cmake's input is checked here, once per page).
const std::string& checked_script(const std::string& code) {
  if (code.find("</script") != std::string::npos || code.find("<!--") != std::string::npos)
    throw std::logic_error("three.js contains </script or <!--: it cannot be inlined as is");
  return code;
}

std::size_t find_token(const std::string& text, const std::string& token) {
  const std::size_t at = text.find(token);
  if (at == std::string::npos) throw std::logic_error("page.html has no " + token);
  return at;
}

}  // namespace

std::string render_page(const nlohmann::json& scene) {
  const std::string page = page_template();
  // Both placeholders are found in the template before anything is inserted, so nothing inside
  // the inserted texts (mesh names, three.js) is ever taken for one. The scene comes first.
  const std::string scene_token = "@@SCENE_JSON@@", three_token = "@@THREE_JS@@";
  const std::size_t scene_at = find_token(page, scene_token), three_at = find_token(page, three_token);
  if (three_at < scene_at) throw std::logic_error("page.html: the scene must come before three.js");
  return page.substr(0, scene_at) + json_for_script(scene) +
         page.substr(scene_at + scene_token.size(), three_at - scene_at - scene_token.size()) +
         checked_script(three_js_source()) + page.substr(three_at + three_token.size());
}

std::filesystem::path write_page(const std::filesystem::path& dir, const nlohmann::json& scene) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw InputError(dir.string() + ": cannot create the directory (" + error.message() + ")");
  const std::filesystem::path path = dir / "index.html";
  const std::string page = render_page(scene);
  std::ofstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open for writing");
  file << page;
  if (!file.flush()) throw InputError(path.string() + ": write failed");
  return path;
}

}  // namespace tightbvh::view
