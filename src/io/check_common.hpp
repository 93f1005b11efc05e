#pragma once
// Helpers shared by the per-format structural checks (check_obj.cpp, check_off.cpp,
// check_stl.cpp, check_ply.cpp): tokenizing, number parsing and error messages. Internal.
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "format_checks.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh::io {

[[noreturn]] inline void fail(const std::string& name, const std::string& problem) {
  throw InputError(name + ": " + problem);
}

inline std::string at_line(std::size_t line) { return "line " + std::to_string(line) + ": "; }

// Shortens a token for an error message: binary garbage must not flood the terminal.
inline std::string quoted(std::string_view token) {
  std::string out;
  for (const char c : token.substr(0, 32)) out += (c >= 32 && c < 127) ? c : '?';
  if (token.size() > 32) out += "...";
  return "'" + out + "'";
}

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

// Splits one line into whitespace-separated tokens (views into the line).
inline std::vector<std::string_view> split(std::string_view line) {
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

inline std::optional<double> parse_double(std::string_view token) {
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
inline void check_coordinates(const std::vector<std::string_view>& tokens, std::size_t first, const Lines& lines,
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

inline bool has_binary_bytes(std::string_view text) {
  return text.substr(0, 1 << 16).find('\0') != std::string_view::npos;
}

inline void check_text(std::string_view text, const std::string& name, const char* format) {
  if (text.size() >= 2 && ((text[0] == '\xFE' && text[1] == '\xFF') || (text[0] == '\xFF' && text[1] == '\xFE')))
    fail(name, std::string("UTF-16 encoded ") + format + " files are not supported (convert to UTF-8)");
  if (has_binary_bytes(text)) fail(name, std::string("binary content: not a text ") + format + " file");
}

inline CheckResult welded() {
  CheckResult result;
  result.weld = true;
  return result;
}

}  // namespace tightbvh::io
