#include "format_checks.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "tightbvh/mesh.hpp"

namespace tightbvh::io {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& problem) {
  throw InputError(name + ": " + problem);
}

std::string at_line(std::size_t line) { return "line " + std::to_string(line) + ": "; }

// Shortens a token for an error message: binary garbage must not flood the terminal.
std::string quoted(std::string_view token) {
  std::string out;
  for (const char c : token.substr(0, 32)) out += (c >= 32 && c < 127) ? c : '?';
  if (token.size() > 32) out += "...";
  return "'" + out + "'";
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

// Splits one line into whitespace-separated tokens (views into the line).
std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

// Iterates over lines with 1-based numbers; strips '#' comments when asked.
class Lines {
 public:
  Lines(std::string_view text, bool strip_comments) : text_(text), strip_(strip_comments) {}
  // The next line that has a token, split; nullopt at the end of the text.
  std::optional<std::vector<std::string_view>> next_nonempty() {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++number_;
      if (strip_) line = line.substr(0, line.find('#'));
      auto tokens = split(line);
      if (!tokens.empty()) return tokens;
    }
    return std::nullopt;
  }
  [[nodiscard]] std::size_t number() const { return number_; }
  // True if nothing but whitespace follows the current line: a short last line means truncation.
  [[nodiscard]] bool at_end() const {
    return pos_ >= text_.size() || text_.find_first_not_of(" \t\r\n", pos_) == std::string_view::npos;
  }

 private:
  std::string_view text_;
  bool strip_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

std::optional<double> parse_double(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (end != token.data() + token.size()) return std::nullopt;
  // Out of double's range: "1e999" overflows (the reader would make it an infinity), "1e-999"
  // underflows to zero, which is harmless.
  if (ec == std::errc::result_out_of_range) {
    const std::string copy(token);
    return std::strtod(copy.c_str(), nullptr);  // ±HUGE_VAL (= ±inf) on overflow, ~0 on underflow
  }
  if (ec != std::errc()) return std::nullopt;
  return value;
}

template <class Int>
std::optional<Int> parse_int(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  Int value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

// Three coordinates at tokens[first..first+2]: numeric and finite.
void check_coordinates(const std::vector<std::string_view>& tokens, std::size_t first, const Lines& lines,
                       const std::string& name, const char* what) {
  const std::size_t line = lines.number();
  if (tokens.size() < first + 3)
    fail(name, at_line(line) + (lines.at_end() ? "truncated file: last " : "malformed ") + what +
                   ": expected 3 coordinates, found " + std::to_string(tokens.size() - first));
  for (std::size_t i = first; i < first + 3; ++i) {
    const std::optional<double> value = parse_double(tokens[i]);
    if (!value) fail(name, at_line(line) + "malformed " + what + ": coordinate " + quoted(tokens[i]) + " is not a number");
    if (!std::isfinite(*value))
      fail(name, at_line(line) + what + " has a non-finite coordinate " + quoted(tokens[i]));
  }
}

bool has_binary_bytes(std::string_view text) {
  return text.substr(0, 1 << 16).find('\0') != std::string_view::npos;
}

void check_text(std::string_view text, const std::string& name, const char* format) {
  if (text.size() >= 2 && ((text[0] == '\xFE' && text[1] == '\xFF') || (text[0] == '\xFF' && text[1] == '\xFE')))
    fail(name, std::string("UTF-16 encoded ") + format + " files are not supported (convert to UTF-8)");
  if (has_binary_bytes(text)) fail(name, std::string("binary content: not a text ") + format + " file");
}

CheckResult welded() {
  CheckResult result;
  result.weld = true;
  return result;
}

}  // namespace

const char* format_name(Format format) {
  switch (format) {
    case Format::obj: return "OBJ";
    case Format::off: return "OFF";
    case Format::stl: return "STL";
    case Format::ply: return "PLY";
  }
  return "?";
}

// ------------------------------------------------------------------------------------------ OBJ
CheckResult check_obj(std::string_view text, const std::string& name) {
  check_text(text, name, "OBJ");
  // assimp refuses files under 16 bytes; none of them can hold a triangle anyway.
  if (text.size() < 16) fail(name, "no triangles: " + std::to_string(text.size()) + " bytes cannot hold a face");
  Lines lines(text, true);
  // Positions, texture coordinates, normals: what the file has so far (relative indices count
  // back from there) and the largest absolute index used, checked at the end.
  struct Kind {
    const char* what;
    const char* plural;
    std::int64_t count = 0;
    std::int64_t max_index = 0;
    std::size_t max_line = 0;
  };
  Kind kinds[3] = {{"vertex", "vertices"}, {"texture coordinate", "texture coordinates"}, {"normal", "normals"}};
  std::uint64_t triangles = 0;
  const auto check_index = [&](std::string_view token, Kind& kind, std::size_t line) {
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
  };
  // A corner "v", "v/vt", "v//vn" or "v/vt/vn"; lines and points allow no normal.
  // Returns the corner's form (which of v, vt, vn it has); a face must use one form throughout.
  const auto check_corner = [&](std::string_view corner, std::size_t line, bool allow_normal) {
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
  };
  const auto check_corners = [&](const std::vector<std::string_view>& tokens, std::size_t line, bool allow_normal) {
    const unsigned form = check_corner(tokens[1], line, allow_normal);
    for (std::size_t i = 2; i < tokens.size(); ++i)
      if (check_corner(tokens[i], line, allow_normal) != form)
        fail(name, at_line(line) + "malformed '" + std::string(tokens[0]) +
                       "' statement: its vertex references mix forms (v, v/vt, v//vn, v/vt/vn)");
  };
  const auto check_numbers = [&](const std::vector<std::string_view>& tokens, std::size_t min, std::size_t max,
                                 std::size_t line) {
    const std::size_t n = tokens.size() - 1;
    if (n < min || n > max)
      fail(name, at_line(line) + "malformed '" + std::string(tokens[0]) + "' statement: " + std::to_string(n) +
                     " values");
    for (std::size_t i = 1; i <= n; ++i)
      if (!parse_double(tokens[i]))
        fail(name, at_line(line) + "malformed '" + std::string(tokens[0]) + "' statement: " + quoted(tokens[i]) +
                       " is not a number");
  };
  while (auto tokens = lines.next_nonempty()) {
    const std::string_view key = (*tokens)[0];
    const std::size_t line = lines.number();
    if (key == "v") {
      check_coordinates(*tokens, 1, lines, name, "vertex");
      // A fourth value is a weight that assimp divides by (x/w, y/w, z/w).
      if (tokens->size() == 5 && (!parse_double((*tokens)[4]) || *parse_double((*tokens)[4]) == 0.0))
        fail(name, at_line(line) + "malformed vertex: weight " + quoted((*tokens)[4]) + " is not a non-zero number");
      ++kinds[0].count;
    } else if (key == "vt") {
      check_numbers(*tokens, 2, 3, line);  // assimp rejects one-component texture coordinates
      ++kinds[1].count;
    } else if (key == "vn") {
      check_numbers(*tokens, 3, 3, line);
      ++kinds[2].count;
    } else if (key == "f") {
      const std::size_t corners = tokens->size() - 1;
      if (corners < 3)
        fail(name, at_line(line) + "malformed face with " + std::to_string(corners) + " vertices (need at least 3)");
      triangles += corners - 2;
      check_corners(*tokens, line, true);
    } else if (key == "l" || key == "p") {
      if (tokens->size() < (key == "l" ? 3u : 2u)) fail(name, at_line(line) + "malformed '" + std::string(key) + "' statement");
      check_corners(*tokens, line, false);
    } else if (key[0] == 'f' || key[0] == 'l' || key[0] == 'p') {
      // assimp takes any statement starting with 'f', 'l' or 'p' for a face, line or point.
      fail(name, at_line(line) + "unknown statement " + quoted(key));
    }
  }
  // Decided here, before assimp: it misreports some face-less files (index errors).
  if (triangles == 0) fail(name, "no triangles: the file has no faces (only points, lines or nothing)");
  for (const Kind& kind : kinds)
    if (kind.max_index > kind.count)
      fail(name, at_line(kind.max_line) + kind.what + " index " + std::to_string(kind.max_index) +
                     " is out of range: the file has " + std::to_string(kind.count) + " " + kind.plural);
  CheckResult result = welded();
  result.expected_triangles = triangles;
  return result;
}

// ------------------------------------------------------------------------------------------ OFF
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

// ------------------------------------------------------------------------------------------ STL
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

// ------------------------------------------------------------------------------------------ PLY
namespace {

struct PlyProperty {
  std::size_t size = 0;        // bytes of the scalar (or of each list item)
  std::size_t count_size = 0;  // 0 for a scalar; bytes of the list's count otherwise
  bool is_float = false;
  bool is_signed = false;
  std::string name;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

std::size_t ply_type_size(std::string_view type, bool& is_float, bool& is_signed) {
  is_float = type == "float" || type == "float32" || type == "double" || type == "float64";
  is_signed = type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" ||
              type == "int32";
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" || type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

// Reads an integer of `size` bytes (list counts and vertex indices) in the file's byte order.
std::int64_t read_binary_int(const char* p, std::size_t size, bool is_signed, bool big_endian) {
  unsigned char b[8] = {};
  std::memcpy(b, p, size);
  if (big_endian) std::reverse(b, b + size);
  std::uint64_t u = 0;
  for (std::size_t i = size; i-- > 0;) u = (u << 8) | b[i];
  if (is_signed && size < 8 && (u >> (8 * size - 1)) != 0) u |= ~std::uint64_t{0} << (8 * size);
  return static_cast<std::int64_t>(u);
}

}  // namespace

CheckResult check_ply(std::string_view bytes, const std::string& name) {
  // Header: printable text lines up to a line "end_header".
  if (bytes.substr(0, 3) != "ply" && bytes.substr(0, 3) != "PLY") fail(name, "not a PLY file: no 'ply' magic number");
  std::size_t header_end = std::string_view::npos;
  for (std::size_t at = bytes.find("\nend_header"); at != std::string_view::npos; at = bytes.find("\nend_header", at + 1)) {
    const std::size_t after = at + 11;
    if (after == bytes.size() || bytes[after] == '\n' || bytes[after] == '\r' || bytes[after] == ' ') {
      header_end = at + 1;
      break;
    }
  }
  if (header_end == std::string_view::npos) fail(name, "malformed PLY header: no 'end_header' line");
  for (std::size_t i = 0; i < header_end; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if ((c < 0x20 || c > 0x7e) && c != '\n' && c != '\r' && c != '\t')
      fail(name, "malformed PLY header: non-text byte " + std::to_string(c) + " at offset " + std::to_string(i));
  }
  std::size_t body = bytes.find('\n', header_end);
  body = body == std::string_view::npos ? bytes.size() : body + 1;

  Lines header(bytes.substr(0, header_end), false);
  header.next_nonempty();  // "ply"
  enum class Encoding { ascii, little, big } encoding = Encoding::ascii;
  bool have_format = false;
  std::vector<PlyElement> elements;
  while (auto tokens = header.next_nonempty()) {
    const std::string_view key = (*tokens)[0];
    const std::size_t line = header.number();
    if (key == "format" && tokens->size() >= 2) {
      const std::string_view f = (*tokens)[1];
      if (f == "ascii") encoding = Encoding::ascii;
      else if (f == "binary_little_endian") encoding = Encoding::little;
      else if (f == "binary_big_endian") encoding = Encoding::big;
      else fail(name, at_line(line) + "malformed PLY header: unknown format " + quoted(f));
      have_format = true;
    } else if (key == "element") {
      if (tokens->size() < 3) fail(name, at_line(line) + "malformed PLY header: element without a count");
      const auto count = parse_int<std::uint64_t>((*tokens)[2]);
      if (!count) fail(name, at_line(line) + "malformed PLY header: element count " + quoted((*tokens)[2]));
      elements.push_back({std::string((*tokens)[1]), *count, {}});
    } else if (key == "property") {
      if (elements.empty()) fail(name, at_line(line) + "malformed PLY header: property before any element");
      PlyProperty p;
      bool count_float = false;
      bool count_signed = false;
      if (tokens->size() >= 5 && (*tokens)[1] == "list") {
        p.count_size = ply_type_size((*tokens)[2], count_float, count_signed);
        p.size = ply_type_size((*tokens)[3], p.is_float, p.is_signed);
        p.name = std::string((*tokens)[4]);
        if (p.count_size == 0 || count_float || p.size == 0)
          fail(name, at_line(line) + "malformed PLY header: bad list property types");
      } else if (tokens->size() >= 3) {
        p.size = ply_type_size((*tokens)[1], p.is_float, p.is_signed);
        p.name = std::string((*tokens)[2]);
        if (p.size == 0) fail(name, at_line(line) + "malformed PLY header: unknown property type " + quoted((*tokens)[1]));
      } else {
        fail(name, at_line(line) + "malformed PLY header: incomplete property");
      }
      elements.back().properties.push_back(std::move(p));
    }
    // Other lines are skipped, as assimp does: real files carry free-text lines (assimp's own
    // PLY/Wuson.ply has a "Created by Blender" line without "comment").
  }
  if (!have_format) fail(name, "malformed PLY header: no 'format' line");

  std::uint64_t expected_triangles = 0;
  std::uint64_t vertex_count = 0;
  std::uint64_t face_count = 0;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") vertex_count = e.count;
    if (e.name == "face") face_count = e.count;
  }
  // A point cloud is sound PLY but not a mesh: say so before judging the rest of the body.
  if (face_count == 0) fail(name, "no triangles: the PLY file has no faces (a point cloud?)");
  // What assimp needs to read a mesh, or it fails, misreads or crashes.
  bool vertex_seen = false;
  for (const PlyElement& e : elements) {
    const auto has = [&e](std::string_view property, bool list) {
      return std::any_of(e.properties.begin(), e.properties.end(),
                         [&](const PlyProperty& p) { return p.name == property && (p.count_size != 0) == list; });
    };
    if (e.name == "vertex") {
      if (!has("x", false) || !has("y", false) || !has("z", false))
        fail(name, "malformed PLY header: the vertex element lacks an x, y or z property");
      vertex_seen = true;
    } else if (e.name == "face") {
      if (!vertex_seen) fail(name, "malformed PLY header: the face element comes before the vertex element");
      if (!has("vertex_indices", true) && !has("vertex_index", true))
        fail(name, "no triangles: the face element has no 'vertex_indices' list");
    }
  }
  // Face lists are the triangles: they need 3+ corners (assimp aborts on empty ones) and valid indices.
  const auto check_face = [&](const PlyElement& e, const PlyProperty& p, std::uint64_t instance, std::int64_t corners,
                              auto&& index_at) {
    if (e.name != "face" || (p.name != "vertex_indices" && p.name != "vertex_index")) return;
    if (corners < 3)
      fail(name, "malformed PLY: face " + std::to_string(instance) + " has " + std::to_string(corners) +
                     " vertices (need at least 3)");
    expected_triangles += static_cast<std::uint64_t>(corners) - 2;
    for (std::int64_t i = 0; i < corners; ++i) {
      const std::int64_t index = index_at(i);
      if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count)
        fail(name, "PLY face " + std::to_string(instance) + ": vertex index " + std::to_string(index) +
                       " is out of range [0, " + std::to_string(vertex_count) + ")");
    }
  };
  const auto truncated = [&](const PlyElement& e, std::uint64_t instance) {
    fail(name, "truncated PLY: the header declares " + std::to_string(e.count) + " " + e.name +
                   " elements but the data ends in element " + std::to_string(instance));
  };

  if (encoding == Encoding::ascii) {
    const std::string_view data = bytes.substr(body);
    if (has_binary_bytes(data)) fail(name, "malformed PLY: binary bytes in an ASCII PLY body");
    // One element per line, as every writer does and assimp's line-based reader requires: values
    // spread over lines make assimp misread the faces (and abort on them).
    Lines lines(data, false);
    const std::size_t header_lines = static_cast<std::size_t>(std::count(bytes.begin(), bytes.begin() + body, '\n'));
    std::vector<std::string_view> tokens;
    std::size_t used = 0;
    const auto next_token = [&]() -> std::optional<std::string_view> {
      if (used == tokens.size()) return std::nullopt;
      return tokens[used++];
    };
    // Cheap first: one line per element, so counts beyond the body's lines are a truncation.
    const std::uint64_t body_lines = static_cast<std::uint64_t>(std::count(data.begin(), data.end(), '\n')) + 1;
    std::uint64_t declared = 0;
    for (const PlyElement& e : elements)
      if (!e.properties.empty()) declared += std::min(e.count, body_lines + 1);
    if (declared > body_lines)
      fail(name, "truncated PLY: the header declares more elements (" + std::to_string(declared) +
                     " or more) than the body has lines (" + std::to_string(body_lines) + ")");
    const auto short_line = [&](const PlyElement& e, std::uint64_t k) {
      if (lines.at_end()) truncated(e, k);
      fail(name, at_line(header_lines + lines.number()) + "malformed PLY: " + e.name + " " + std::to_string(k) +
                     " has fewer values than the header declares");
    };
    for (const PlyElement& e : elements) {
      if (e.properties.empty()) continue;  // no data, however large the count
      for (std::uint64_t k = 0; k < e.count; ++k) {
        auto line = lines.next_nonempty();
        if (!line) truncated(e, k);
        tokens = std::move(*line);
        used = 0;
        for (const PlyProperty& p : e.properties) {
          if (p.count_size == 0) {
            const auto token = next_token();
            if (!token) short_line(e, k);
            if (!parse_double(*token)) fail(name, "malformed PLY: " + e.name + " value " + quoted(*token) + " is not a number");
            continue;
          }
          const auto count_token = next_token();
          if (!count_token) short_line(e, k);
          const auto corners = parse_int<std::int64_t>(*count_token);
          if (!corners || *corners < 0)
            fail(name, "malformed PLY: list length " + quoted(*count_token) + " in " + e.name + " " + std::to_string(k));
          std::vector<std::int64_t> items;
          for (std::int64_t i = 0; i < *corners; ++i) {
            const auto token = next_token();
            if (!token) short_line(e, k);
            const auto value = parse_double(*token);
            if (!value) fail(name, "malformed PLY: list item " + quoted(*token) + " is not a number");
            // Clamped before the cast (a cast of NaN or 1e300 is undefined); out of range either way.
            items.push_back(std::isfinite(*value) && std::abs(*value) < 9e18 ? static_cast<std::int64_t>(*value) : -1);
          }
          check_face(e, p, k, *corners, [&](std::int64_t i) { return items[static_cast<std::size_t>(i)]; });
        }
        if (used != tokens.size())
          fail(name, at_line(header_lines + lines.number()) + "malformed PLY: " + e.name + " " + std::to_string(k) +
                         " has more values than the header declares");
      }
    }
  } else {
    const bool big = encoding == Encoding::big;
    std::size_t pos = body;
    for (const PlyElement& e : elements) {
      // Fixed-size elements are checked in one step, so a huge declared count costs nothing.
      const bool fixed = std::all_of(e.properties.begin(), e.properties.end(),
                                     [](const PlyProperty& p) { return p.count_size == 0; });
      if (fixed) {
        std::uint64_t stride = 0;
        for (const PlyProperty& p : e.properties) stride += p.size;
        const std::uint64_t available = bytes.size() - pos;
        if (stride != 0 && e.count > available / stride) truncated(e, available / stride);
        pos += static_cast<std::size_t>(stride * e.count);
        continue;
      }
      for (std::uint64_t k = 0; k < e.count; ++k) {
        for (const PlyProperty& p : e.properties) {
          if (p.count_size == 0) {
            if (bytes.size() - pos < p.size) truncated(e, k);
            pos += p.size;
            continue;
          }
          if (bytes.size() - pos < p.count_size) truncated(e, k);
          const std::int64_t corners = read_binary_int(bytes.data() + pos, p.count_size, false, big);
          pos += p.count_size;
          if (static_cast<std::uint64_t>(corners) > (bytes.size() - pos) / p.size) truncated(e, k);
          const char* items = bytes.data() + pos;
          if (!p.is_float)
            check_face(e, p, k, corners, [&](std::int64_t i) {
              return read_binary_int(items + i * static_cast<std::int64_t>(p.size), p.size, p.is_signed, big);
            });
          pos += static_cast<std::size_t>(corners) * p.size;
        }
      }
    }
  }
  CheckResult result;
  result.expected_triangles = expected_triangles;
  return result;
}

// ------------------------------------------------------------------------------------------ sniffing
bool sniff_format(std::string_view bytes, Format& format) {
  if (bytes.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    if (84 + 50 * std::uint64_t{n} == bytes.size()) {
      format = Format::stl;
      return true;
    }
  }
  Lines lines(bytes.substr(0, 4096), true);
  const auto first = lines.next_nonempty();
  if (!first) return false;
  const std::string_view key = (*first)[0];
  if (key == "ply" || key == "PLY") format = Format::ply;
  else if (key.size() >= 3 && key.substr(key.size() - 3) == "OFF") format = Format::off;
  else if (key == "solid") format = Format::stl;
  else if (key == "v" || key == "o" || key == "g" || key == "mtllib" || key == "vn" || key == "vt") format = Format::obj;
  else return false;
  return true;
}

}  // namespace tightbvh::io
