#pragma once
// Option help and error texts from the library's name tables (fit.hpp, split.hpp, build.hpp),
// so that a new method shows up in every command without editing it.
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tightbvh::cli {

// "a | b | c": the choices of an option, in its help text.
[[nodiscard]] inline std::string choices(std::span<const std::string_view> names) {
  std::string out;
  for (const std::string_view name : names) out += (out.empty() ? "" : " | ") + std::string(name);
  return out;
}

// "a, b or c": the choices in an error message.
[[nodiscard]] inline std::string one_of(std::span<const std::string_view> names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + std::string(names[i]);
  return out;
}

// The names followed by `extra` (e.g. "all").
[[nodiscard]] inline std::vector<std::string_view> with(std::span<const std::string_view> names,
                                                        std::string_view extra) {
  std::vector<std::string_view> out(names.begin(), names.end());
  out.push_back(extra);
  return out;
}

}  // namespace tightbvh::cli
