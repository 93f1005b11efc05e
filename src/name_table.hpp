#pragma once
// Internal: the one table of an enum's names (fit methods, split methods), from which parsing,
// to_string, the CLI help texts and "--method all" lists all come.
#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <utility>

namespace tightbvh::detail {

template <class Enum, std::size_t N>
class NameTable {
 public:
  constexpr explicit NameTable(const std::array<std::pair<Enum, std::string_view>, N>& rows) {
    for (std::size_t i = 0; i < N; ++i) values_[i] = rows[i].first, names_[i] = rows[i].second;
  }
  [[nodiscard]] constexpr std::optional<Enum> parse(std::string_view name) const {
    for (std::size_t i = 0; i < N; ++i)
      if (names_[i] == name) return values_[i];
    return std::nullopt;
  }
  [[nodiscard]] constexpr std::string_view name(Enum value) const {
    for (std::size_t i = 0; i < N; ++i)
      if (values_[i] == value) return names_[i];
    return "unknown";
  }
  [[nodiscard]] constexpr std::span<const Enum> values() const { return values_; }
  [[nodiscard]] constexpr std::span<const std::string_view> names() const { return names_; }

 private:
  std::array<Enum, N> values_{};
  std::array<std::string_view, N> names_{};
};

}  // namespace tightbvh::detail
