// Structural checks of ASCII and binary PLY files, in phases: the header's extent, its lines
// (format, elements, properties), the layout assimp needs, then the body (ASCII or binary).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "check_common.hpp"

namespace tightbvh::io {
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
  size = std::min(size, sizeof b);  // callers pass scalar_size(), at most 8
  std::memcpy(b, p, size);
  if (big_endian) std::reverse(b, b + size);
  std::uint64_t u = 0;
  for (std::size_t i = size; i-- > 0;) u = (u << 8) | b[i];
  if (is_signed && size < 8 && (u >> (8 * size - 1)) != 0) u |= ~std::uint64_t{0} << (8 * size);
  return static_cast<std::int64_t>(u);
}


enum class Encoding { ascii, little, big };

struct PlyHeader {
  Encoding encoding = Encoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t end = 0;   // offset just past the "\n" before "end_header"
  std::size_t body = 0;  // offset of the first byte after the "end_header" line
};

// Phase 1: the header is printable text lines up to a line "end_header". Returns the offset of
// that line.
std::size_t find_header_end(std::string_view bytes, const std::string& name) {
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
  return header_end;
}

// A "property <type> <name>" or "property list <count type> <item type> <name>" line.
PlyProperty parse_property(const std::vector<std::string_view>& tokens, std::size_t line, const std::string& name) {
  PlyProperty p;
  bool count_float = false;
  bool count_signed = false;
  if (tokens.size() >= 5 && tokens[1] == "list") {
    p.count_size = ply_type_size(tokens[2], count_float, count_signed);
    p.size = ply_type_size(tokens[3], p.is_float, p.is_signed);
    p.name = std::string(tokens[4]);
    if (p.count_size == 0 || count_float || p.size == 0)
      fail(name, at_line(line) + "malformed PLY header: bad list property types");
  } else if (tokens.size() >= 3) {
    p.size = ply_type_size(tokens[1], p.is_float, p.is_signed);
    p.name = std::string(tokens[2]);
    if (p.size == 0) fail(name, at_line(line) + "malformed PLY header: unknown property type " + quoted(tokens[1]));
  } else {
    fail(name, at_line(line) + "malformed PLY header: incomplete property");
  }
  return p;
}

// Phase 2: the header's lines: encoding, elements and their properties.
PlyHeader parse_header(std::string_view bytes, const std::string& name) {
  PlyHeader header;
  header.end = find_header_end(bytes, name);
  const std::size_t body = bytes.find('\n', header.end);
  header.body = body == std::string_view::npos ? bytes.size() : body + 1;

  Lines lines(bytes.substr(0, header.end), false);
  lines.next_nonempty();  // "ply"
  bool have_format = false;
  while (auto tokens = lines.next_nonempty()) {
    const std::string_view key = (*tokens)[0];
    const std::size_t line = lines.number();
    if (key == "format" && tokens->size() >= 2) {
      const std::string_view f = (*tokens)[1];
      if (f == "ascii") header.encoding = Encoding::ascii;
      else if (f == "binary_little_endian") header.encoding = Encoding::little;
      else if (f == "binary_big_endian") header.encoding = Encoding::big;
      else fail(name, at_line(line) + "malformed PLY header: unknown format " + quoted(f));
      have_format = true;
    } else if (key == "element") {
      if (tokens->size() < 3) fail(name, at_line(line) + "malformed PLY header: element without a count");
      const auto count = parse_int<std::uint64_t>((*tokens)[2]);
      if (!count) fail(name, at_line(line) + "malformed PLY header: element count " + quoted((*tokens)[2]));
      header.elements.push_back({std::string((*tokens)[1]), *count, {}});
    } else if (key == "property") {
      if (header.elements.empty()) fail(name, at_line(line) + "malformed PLY header: property before any element");
      header.elements.back().properties.push_back(parse_property(*tokens, line, name));
    }
    // Other lines are skipped, as assimp does: real files carry free-text lines (assimp's own
    // PLY/Wuson.ply has a "Created by Blender" line without "comment").
  }
  if (!have_format) fail(name, "malformed PLY header: no 'format' line");
  return header;
}

// Phase 3: what assimp needs to read a mesh, or it fails, misreads or crashes. Returns the
// vertex count (0 without a vertex element).
std::uint64_t check_layout(const std::vector<PlyElement>& elements, const std::string& name) {
  std::uint64_t vertex_count = 0;
  std::uint64_t face_count = 0;
  for (const PlyElement& e : elements) {
    if (e.name == "vertex") vertex_count = e.count;
    if (e.name == "face") face_count = e.count;
  }
  // A point cloud is sound PLY but not a mesh: say so before judging the rest of the body.
  if (face_count == 0) fail(name, "no triangles: the PLY file has no faces (a point cloud?)");
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
  return vertex_count;
}

// Phase 4 (both encodings): face lists are the triangles; they need 3+ corners (assimp aborts
// on empty ones) and valid indices. Counts the triangles they make.
struct FaceCheck {
  const std::string& name;
  std::uint64_t vertex_count = 0;
  std::uint64_t expected_triangles = 0;

  template <class IndexAt>
  void operator()(const PlyElement& e, const PlyProperty& p, std::uint64_t instance, std::int64_t corners,
                  IndexAt&& index_at) {
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
  }
  [[noreturn]] void truncated(const PlyElement& e, std::uint64_t instance) const {
    fail(name, "truncated PLY: the header declares " + std::to_string(e.count) + " " + e.name +
                   " elements but the data ends in element " + std::to_string(instance));
  }
};

// The ASCII body, one element per line: the line's tokens and how many are used so far.
struct AsciiElementLine {
  std::vector<std::string_view> tokens;
  std::size_t used = 0;
  std::optional<std::string_view> next() {
    if (used == tokens.size()) return std::nullopt;
    return tokens[used++];
  }
};

// Phase 4, ASCII: one element per line, as every writer does and assimp's line-based reader
// requires: values spread over lines make assimp misread the faces (and abort on them).
void check_ascii_body(std::string_view bytes, const PlyHeader& header, FaceCheck& faces) {
  const std::string& name = faces.name;
  const std::string_view data = bytes.substr(header.body);
  if (has_binary_bytes(data)) fail(name, "malformed PLY: binary bytes in an ASCII PLY body");
  Lines lines(data, false);
  const std::size_t header_lines =
      static_cast<std::size_t>(std::count(bytes.begin(), bytes.begin() + header.body, '\n'));
  // Cheap first: one line per element, so counts beyond the body's lines are a truncation.
  const std::uint64_t body_lines = static_cast<std::uint64_t>(std::count(data.begin(), data.end(), '\n')) + 1;
  std::uint64_t declared = 0;
  for (const PlyElement& e : header.elements)
    if (!e.properties.empty()) declared += std::min(e.count, body_lines + 1);
  if (declared > body_lines)
    fail(name, "truncated PLY: the header declares more elements (" + std::to_string(declared) +
                   " or more) than the body has lines (" + std::to_string(body_lines) + ")");
  const auto short_line = [&](const PlyElement& e, std::uint64_t k) {
    if (lines.at_end()) faces.truncated(e, k);
    fail(name, at_line(header_lines + lines.number()) + "malformed PLY: " + e.name + " " + std::to_string(k) +
                   " has fewer values than the header declares");
  };
  AsciiElementLine line;
  for (const PlyElement& e : header.elements) {
    if (e.properties.empty()) continue;  // no data, however large the count
    for (std::uint64_t k = 0; k < e.count; ++k) {
      auto tokens = lines.next_nonempty();
      if (!tokens) faces.truncated(e, k);
      line.tokens = std::move(*tokens);
      line.used = 0;
      for (const PlyProperty& p : e.properties) {
        if (p.count_size == 0) {
          const auto token = line.next();
          if (!token) short_line(e, k);
          if (!parse_double(*token)) fail(name, "malformed PLY: " + e.name + " value " + quoted(*token) + " is not a number");
          continue;
        }
        const auto count_token = line.next();
        if (!count_token) short_line(e, k);
        const auto corners = parse_int<std::int64_t>(*count_token);
        if (!corners || *corners < 0)
          fail(name, "malformed PLY: list length " + quoted(*count_token) + " in " + e.name + " " + std::to_string(k));
        std::vector<std::int64_t> items;
        for (std::int64_t i = 0; i < *corners; ++i) {
          const auto token = line.next();
          if (!token) short_line(e, k);
          const auto value = parse_double(*token);
          if (!value) fail(name, "malformed PLY: list item " + quoted(*token) + " is not a number");
          // Clamped before the cast (a cast of NaN or 1e300 is undefined); out of range either way.
          items.push_back(std::isfinite(*value) && std::abs(*value) < 9e18 ? static_cast<std::int64_t>(*value) : -1);
        }
        faces(e, p, k, *corners, [&](std::int64_t i) { return items[static_cast<std::size_t>(i)]; });
      }
      if (line.used != line.tokens.size())
        fail(name, at_line(header_lines + lines.number()) + "malformed PLY: " + e.name + " " + std::to_string(k) +
                       " has more values than the header declares");
    }
  }
}

// Phase 4, binary: walks the elements by their byte sizes; only list properties need a look.
void check_binary_body(std::string_view bytes, const PlyHeader& header, FaceCheck& faces) {
  const bool big = header.encoding == Encoding::big;
  std::size_t pos = header.body;
  for (const PlyElement& e : header.elements) {
    // Fixed-size elements are checked in one step, so a huge declared count costs nothing.
    const bool fixed = std::all_of(e.properties.begin(), e.properties.end(),
                                   [](const PlyProperty& p) { return p.count_size == 0; });
    if (fixed) {
      std::uint64_t stride = 0;
      for (const PlyProperty& p : e.properties) stride += p.size;
      const std::uint64_t available = bytes.size() - pos;
      if (stride != 0 && e.count > available / stride) faces.truncated(e, available / stride);
      pos += static_cast<std::size_t>(stride * e.count);
      continue;
    }
    for (std::uint64_t k = 0; k < e.count; ++k) {
      for (const PlyProperty& p : e.properties) {
        if (p.count_size == 0) {
          if (bytes.size() - pos < p.size) faces.truncated(e, k);
          pos += p.size;
          continue;
        }
        if (bytes.size() - pos < p.count_size) faces.truncated(e, k);
        const std::int64_t corners = read_binary_int(bytes.data() + pos, p.count_size, false, big);
        pos += p.count_size;
        if (static_cast<std::uint64_t>(corners) > (bytes.size() - pos) / p.size) faces.truncated(e, k);
        const char* items = bytes.data() + pos;
        if (!p.is_float)
          faces(e, p, k, corners, [&](std::int64_t i) {
            return read_binary_int(items + i * static_cast<std::int64_t>(p.size), p.size, p.is_signed, big);
          });
        pos += static_cast<std::size_t>(corners) * p.size;
      }
    }
  }
}

}  // namespace

CheckResult check_ply(std::string_view bytes, const std::string& name) {
  const PlyHeader header = parse_header(bytes, name);
  FaceCheck faces{name, check_layout(header.elements, name)};
  if (header.encoding == Encoding::ascii) check_ascii_body(bytes, header, faces);
  else check_binary_body(bytes, header, faces);
  CheckResult result;
  result.expected_triangles = faces.expected_triangles;
  return result;
}

}  // namespace tightbvh::io
