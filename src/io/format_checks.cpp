// Format names and content sniffing; the per-format checks live in check_<format>.cpp.
#include "format_checks.hpp"

#include <cstdint>
#include <cstring>

#include "check_common.hpp"

namespace tightbvh::io {

const char* format_name(Format format) {
  switch (format) {
    case Format::obj: return "OBJ";
    case Format::off: return "OFF";
    case Format::stl: return "STL";
    case Format::ply: return "PLY";
  }
  return "?";
}

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
