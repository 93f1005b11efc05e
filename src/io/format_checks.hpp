#pragma once
// Structural checks of mesh files, run before assimp sees them.
//
// Why: assimp 5.2 "repairs" some broken files instead of failing (clamps out-of-range OFF
// indices, reads a truncated ASCII PLY partially), allocates whatever a header asks for (an OFF
// header with 3.5e11 vertices takes ~16 GB before failing) and aborts the process through
// ai_assert on some malformed input (zero-length faces, truncated OFF). These checks walk the
// file once, allocate nothing proportional to header counts, and throw a precise InputError.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tightbvh::io {

enum class Format { obj, off, stl, ply };

[[nodiscard]] const char* format_name(Format format);

// What the checks learnt about the file, beyond "it is sound".
struct CheckResult {
  // True when assimp splits the file's shared vertices per face corner (OBJ, STL), so the loader
  // welds exactly equal positions back together.
  bool weld = false;
  // OFF only: the file rewritten as plain "OFF" with comments, colours, normals and texture
  // coordinates dropped (tokens copied verbatim, so no precision is lost). assimp 5.2 rejects
  // valid OFF variants such as COFF with RGB instead of RGBA colours or comments after values.
  std::string normalized;
  // Triangles the file's polygons make (a k-gon gives k - 2); 0 if unknown. assimp 5.2 drops the
  // rest of a polygon it cannot ear-clip (non-simple polygons) and only logs it: the loader
  // compares its result with this count.
  std::uint64_t expected_triangles = 0;
  // OFF only: the vertices parsed in double precision (assimp reads single precision).
  std::vector<std::array<double, 3>> precise_vertices;
};

// `name` prefixes every message ("<name>: <problem>"). Throws tightbvh::InputError.
[[nodiscard]] CheckResult check_obj(std::string_view text, const std::string& name);
[[nodiscard]] CheckResult check_off(std::string_view text, const std::string& name);
[[nodiscard]] CheckResult check_stl(std::string_view bytes, const std::string& name);
[[nodiscard]] CheckResult check_ply(std::string_view bytes, const std::string& name);

// Guesses the format of a file without a known extension from its first bytes; false if none fits.
[[nodiscard]] bool sniff_format(std::string_view bytes, Format& format);

}  // namespace tightbvh::io
