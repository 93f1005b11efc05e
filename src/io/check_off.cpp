// Structural checks of OFF files; also normalizes the text for assimp and keeps double-precision
// vertices (see CheckResult).
#include <cstdint>
#include <string>
#include <string_view>

#include "check_common.hpp"

namespace tightbvh::io {

CheckResult check_off(std::string_view text, const std::string& name) {
  if (has_binary_bytes(text)) fail(name, "binary content: not a text OFF file (binary OFF is not supported)");
  Lines lines(text, true);
  auto header = lines.next_nonempty();
  if (!header) fail(name, "no OFF header");
  const std::string_view key = (*header)[0];
  if (key.size() < 3 || key.substr(key.size() - 3) != "OFF")
    fail(name, "not an OFF file: expected an 'OFF' header, found " + quoted(key));
  const std::string_view prefix = key.substr(0, key.size() - 3);
  if (prefix.find_first_not_of("STCN") != std::string_view::npos)
    fail(name, "unsupported OFF variant " + quoted(key) + " (only 3D OFF, COFF, NOFF, STOFF are read)");

  std::vector<std::string_view> counts(header->begin() + 1, header->end());
  if (!counts.empty() && counts[0] == "BINARY") fail(name, "binary OFF is not supported");
  if (counts.empty()) {
    auto next = lines.next_nonempty();
    if (!next) fail(name, "truncated OFF: the file ends before the vertex and face counts");
    counts = *next;
  }
  const std::size_t counts_line = lines.number();
  if (counts.size() < 2) fail(name, at_line(counts_line) + "malformed OFF header: expected vertex and face counts");
  const auto nv = parse_int<std::uint64_t>(counts[0]);
  const auto nf = parse_int<std::uint64_t>(counts[1]);
  if (!nv || !nf)
    fail(name, at_line(counts_line) + "malformed OFF header: counts " + quoted(counts[0]) + " " + quoted(counts[1]) +
                   " are not non-negative integers");
  if (*nf == 0) fail(name, "no triangles: the OFF header declares 0 faces");
  CheckResult result;
  std::string& out = result.normalized;
  out.reserve(text.size());
  out += "OFF\n" + std::to_string(*nv) + " " + std::to_string(*nf) + " 0\n";
  const auto emit = [&out](const std::vector<std::string_view>& tokens, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) {
      out += tokens[i];
      out += i + 1 < count ? ' ' : '\n';
    }
  };

  for (std::uint64_t v = 0; v < *nv; ++v) {
    auto tokens = lines.next_nonempty();
    if (!tokens)
      fail(name, "truncated OFF: the header declares " + std::to_string(*nv) + " vertices and " + std::to_string(*nf) +
                     " faces but the file ends after " + std::to_string(v) + " vertices");
    check_coordinates(*tokens, 0, lines, name, "vertex");
    emit(*tokens, 3);
    result.precise_vertices.push_back({*parse_double((*tokens)[0]), *parse_double((*tokens)[1]), *parse_double((*tokens)[2])});
  }
  for (std::uint64_t f = 0; f < *nf; ++f) {
    auto tokens = lines.next_nonempty();
    if (!tokens)
      fail(name, "truncated OFF: the header declares " + std::to_string(*nf) + " faces but the file ends after " +
                     std::to_string(f));
    const std::size_t line = lines.number();
    const auto corners = parse_int<std::uint64_t>((*tokens)[0]);
    if (!corners) fail(name, at_line(line) + "malformed face: vertex count " + quoted((*tokens)[0]) + " is not an integer");
    if (*corners < 3)
      fail(name, at_line(line) + "malformed face with " + std::to_string(*corners) + " vertices (need at least 3)");
    if (tokens->size() - 1 < *corners)
      fail(name, at_line(line) + (lines.at_end() ? "truncated OFF: last face declares " : "malformed face: declares ") + std::to_string(*corners) + " vertices but lists " +
                     std::to_string(tokens->size() - 1));
    for (std::size_t i = 1; i <= *corners; ++i) {
      const auto index = parse_int<std::int64_t>((*tokens)[i]);
      if (!index) fail(name, at_line(line) + "malformed face: index " + quoted((*tokens)[i]) + " is not an integer");
      if (*index < 0 || static_cast<std::uint64_t>(*index) >= *nv)
        fail(name, at_line(line) + "face index " + std::to_string(*index) + " is out of range [0, " + std::to_string(*nv) +
                       ")");
    }
    emit(*tokens, *corners + 1);
    result.expected_triangles += *corners - 2;
  }
  return result;
}

}  // namespace tightbvh::io
