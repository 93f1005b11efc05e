// Structural checks of OBJ files (see format_checks.hpp for why they run before assimp).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "check_common.hpp"

namespace tightbvh::io {
namespace {

// Positions, texture coordinates, normals: what the file has so far (relative indices count
// back from there) and the largest absolute index used, checked at the end.
struct Kind {
  const char* what;
  const char* plural;
  std::int64_t count = 0;
  std::int64_t max_index = 0;
  std::size_t max_line = 0;
};

// The state of one pass over the file's statements.
struct ObjChecker {
  const std::string& name;
  Kind kinds[3] = {{"vertex", "vertices"}, {"texture coordinate", "texture coordinates"}, {"normal", "normals"}};
  std::uint64_t triangles = 0;

  void check_index(std::string_view token, Kind& kind, std::size_t line) const {
    const auto index = parse_int<std::int64_t>(token);
    if (!index) fail(name, at_line(line) + "malformed " + kind.what + " index " + quoted(token));
    if (*index == 0) fail(name, at_line(line) + kind.what + " index 0 is out of range (OBJ indices start at 1)");
    if (*index < -kind.count)
      fail(name, at_line(line) + "relative " + kind.what + " index " + std::to_string(*index) +
                     " is out of range: only " + std::to_string(kind.count) + " " + kind.plural + " precede it");
    if (*index > kind.max_index) {
      kind.max_index = *index;
      kind.max_line = line;
    }
  }

  // A corner "v", "v/vt", "v//vn" or "v/vt/vn"; lines and points allow no normal.
  // Returns the corner's form (which of v, vt, vn it has); a face must use one form throughout.
  unsigned check_corner(std::string_view corner, std::size_t line, bool allow_normal) {
    const std::string_view whole = corner;
    std::size_t part = 0;
    unsigned form = 0;
    while (true) {
      const std::size_t slash = corner.find('/');
      const std::string_view token = corner.substr(0, slash);
      if (part == 0 || !token.empty()) {
        check_index(token, kinds[part], line);
        form |= 1u << part;
      }
      if (slash == std::string_view::npos) break;
      corner.remove_prefix(slash + 1);
      if (++part > (allow_normal ? 2u : 1u)) fail(name, at_line(line) + "malformed vertex reference: too many '/'");
    }
    if (part != 0 && form == 1u) fail(name, at_line(line) + "malformed vertex reference " + quoted(whole));
    return form;
  }

  void check_corners(const std::vector<std::string_view>& tokens, std::size_t line, bool allow_normal) {
    const unsigned form = check_corner(tokens[1], line, allow_normal);
    for (std::size_t i = 2; i < tokens.size(); ++i)
      if (check_corner(tokens[i], line, allow_normal) != form)
        fail(name, at_line(line) + "malformed '" + std::string(tokens[0]) +
                       "' statement: its vertex references mix forms (v, v/vt, v//vn, v/vt/vn)");
  }

  void check_numbers(const std::vector<std::string_view>& tokens, std::size_t min, std::size_t max,
                     std::size_t line) const {
    const std::size_t n = tokens.size() - 1;
    if (n < min || n > max)
      fail(name, at_line(line) + "malformed '" + std::string(tokens[0]) + "' statement: " + std::to_string(n) +
                     " values");
    for (std::size_t i = 1; i <= n; ++i)
      if (!parse_double(tokens[i]))
        fail(name, at_line(line) + "malformed '" + std::string(tokens[0]) + "' statement: " + quoted(tokens[i]) +
                       " is not a number");
  }

  // One statement; statements other than geometry and elements are assimp's business.
  void check_statement(const std::vector<std::string_view>& tokens, const Lines& lines) {
    const std::string_view key = tokens[0];
    const std::size_t line = lines.number();
    if (key == "v") {
      check_coordinates(tokens, 1, lines, name, "vertex");
      // A fourth value is a weight that assimp divides by (x/w, y/w, z/w).
      if (tokens.size() == 5 && (!parse_double(tokens[4]) || *parse_double(tokens[4]) == 0.0))
        fail(name, at_line(line) + "malformed vertex: weight " + quoted(tokens[4]) + " is not a non-zero number");
      ++kinds[0].count;
    } else if (key == "vt") {
      check_numbers(tokens, 2, 3, line);  // assimp rejects one-component texture coordinates
      ++kinds[1].count;
    } else if (key == "vn") {
      check_numbers(tokens, 3, 3, line);
      ++kinds[2].count;
    } else if (key == "f") {
      const std::size_t corners = tokens.size() - 1;
      if (corners < 3)
        fail(name, at_line(line) + "malformed face with " + std::to_string(corners) + " vertices (need at least 3)");
      triangles += corners - 2;
      check_corners(tokens, line, true);
    } else if (key == "l" || key == "p") {
      if (tokens.size() < (key == "l" ? 3u : 2u)) fail(name, at_line(line) + "malformed '" + std::string(key) + "' statement");
      check_corners(tokens, line, false);
    } else if (key[0] == 'f' || key[0] == 'l' || key[0] == 'p') {
      // assimp takes any statement starting with 'f', 'l' or 'p' for a face, line or point.
      fail(name, at_line(line) + "unknown statement " + quoted(key));
    }
  }

  // After the last statement: faces exist and absolute indices stay within the final counts.
  void check_totals() const {
    // Decided here, before assimp: it misreports some face-less files (index errors).
    if (triangles == 0) fail(name, "no triangles: the file has no faces (only points, lines or nothing)");
    for (const Kind& kind : kinds)
      if (kind.max_index > kind.count)
        fail(name, at_line(kind.max_line) + kind.what + " index " + std::to_string(kind.max_index) +
                       " is out of range: the file has " + std::to_string(kind.count) + " " + kind.plural);
  }
};

}  // namespace

CheckResult check_obj(std::string_view text, const std::string& name) {
  check_text(text, name, "OBJ");
  // assimp refuses files under 16 bytes; none of them can hold a triangle anyway.
  if (text.size() < 16) fail(name, "no triangles: " + std::to_string(text.size()) + " bytes cannot hold a face");
  Lines lines(text, true);
  ObjChecker checker{name};
  while (auto tokens = lines.next_nonempty()) checker.check_statement(*tokens, lines);
  checker.check_totals();
  CheckResult result = welded();
  result.expected_triangles = checker.triangles;
  return result;
}

}  // namespace tightbvh::io
