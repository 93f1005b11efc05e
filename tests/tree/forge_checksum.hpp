#pragma once
// The tree format's checksum (serialize.hpp: FNV-1a 64 over bytes [16, 32) and [40, end), stored
// at [32, 40)), written out independently of the library so that tests and the fuzz target can
// forge files whose checksum is right but whose content is wrong.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tightbvh::test {

inline void fix_checksum(std::vector<std::byte>& bytes) {
  std::uint64_t h = 14695981039346656037ull;
  const auto mix = [&h](std::byte b) { h = (h ^ std::to_integer<std::uint8_t>(b)) * 1099511628211ull; };
  for (std::size_t i = 16; i < 32; ++i) mix(bytes[i]);
  for (std::size_t i = 40; i < bytes.size(); ++i) mix(bytes[i]);
  for (int i = 0; i < 8; ++i) bytes[32 + i] = std::byte((h >> (8 * i)) & 0xff);
}

}  // namespace tightbvh::test
