// Structural checks of binary and ASCII STL files.
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

#include "check_common.hpp"

namespace tightbvh::io {

CheckResult check_stl(std::string_view bytes, const std::string& name) {
  constexpr std::uint64_t header = 84;
  constexpr std::uint64_t facet = 50;
  std::optional<std::uint64_t> declared;
  if (bytes.size() >= header) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);  // little-endian on every platform we build for
    declared = n;
    if (header + facet * n == bytes.size()) {  // a well-formed binary STL
      if (n == 0) fail(name, "no triangles: the binary STL declares 0 triangles");
      return welded();
    }
  }
  std::size_t start = 0;
  while (start < bytes.size() && is_space(bytes[start])) ++start;
  const bool ascii = bytes.substr(start, 5) == "solid" && !has_binary_bytes(bytes);
  if (!ascii) {
    if (!declared)
      fail(name, "not a valid STL file: " + std::to_string(bytes.size()) +
                     " bytes is too small for a binary STL and there is no ASCII 'solid' header");
    const std::uint64_t expected = header + facet * *declared;
    if (bytes.size() < expected)
      fail(name, "truncated binary STL (or not an STL file): the header declares " + std::to_string(*declared) +
                     " triangles (" + std::to_string(expected) + " bytes) but the file has " +
                     std::to_string(bytes.size()) + " bytes");
    fail(name, "malformed binary STL: the header declares " + std::to_string(*declared) + " triangles (" +
                   std::to_string(expected) + " bytes) but the file has " + std::to_string(bytes.size() - expected) +
                   " extra bytes");
  }
  // ASCII: every solid must be closed and every facet must have three vertices.
  Lines lines(bytes, false);
  std::size_t open_solids = 0;
  std::size_t solids = 0;
  std::size_t facet_vertices = 0;
  std::size_t facets = 0;
  bool in_facet = false;
  while (auto tokens = lines.next_nonempty()) {
    const std::string_view key = (*tokens)[0];
    const std::size_t line = lines.number();
    if (key == "solid") {
      ++open_solids;
      ++solids;
    } else if (key == "endsolid") {
      if (open_solids == 0) fail(name, at_line(line) + "malformed ASCII STL: 'endsolid' without 'solid'");
      --open_solids;
    } else if (key == "facet") {
      // assimp leaks and fails (or misreads) on anything but "facet normal x y z".
      if (tokens->size() != 5 || (*tokens)[1] != "normal" || !parse_double((*tokens)[2]) ||
          !parse_double((*tokens)[3]) || !parse_double((*tokens)[4]))
        fail(name, at_line(line) + (lines.at_end() ? "truncated" : "malformed") +
                       " ASCII STL: expected 'facet normal <x> <y> <z>'");
      if (in_facet) fail(name, at_line(line) + "malformed ASCII STL: 'facet' inside a facet");
      in_facet = true;
      ++facets;
      facet_vertices = 0;
    } else if (key == "vertex") {
      check_coordinates(*tokens, 1, lines, name, "vertex");
      if (tokens->size() != 4 || !in_facet)
        fail(name, at_line(line) + "malformed ASCII STL: expected 'vertex <x> <y> <z>' inside a facet");
      ++facet_vertices;
    } else if (key == "endfacet") {
      if (!in_facet || facet_vertices != 3)
        fail(name, at_line(line) + "malformed ASCII STL: facet with " + std::to_string(facet_vertices) +
                       " vertices (need 3)");
      in_facet = false;
    }
  }
  if (in_facet || open_solids != 0)
    fail(name, "truncated ASCII STL: the file ends inside a " + std::string(in_facet ? "facet" : "solid") +
                   " (no closing 'endsolid')");
  if (solids == 0) fail(name, "malformed ASCII STL: no 'solid' statement");
  if (facets == 0) fail(name, "no triangles: the ASCII STL has no facets");
  return welded();
}

}  // namespace tightbvh::io
