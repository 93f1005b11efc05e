#include "tightbvh/serialize.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <ostream>

#include "tightbvh/mesh.hpp"
#include "tightbvh/validate_tree.hpp"

namespace tightbvh {
namespace {

constexpr std::array<char, 8> kMagic{'T', 'B', 'V', 'H', 'T', 'R', 'E', 'E'};
constexpr std::size_t kHeaderSize = 40;
constexpr std::size_t kNodeSize = 15 * 4 + 2 * 4;  // 68
constexpr std::size_t kChecksumOffset = 32;

// Explicit little-endian encoding: the file is the same on every host.
void put_u32(std::byte* out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out[i] = std::byte((v >> (8 * i)) & 0xff);
}
void put_u64(std::byte* out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out[i] = std::byte((v >> (8 * i)) & 0xff);
}
[[nodiscard]] std::uint32_t get_u32(const std::byte* in) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t(std::to_integer<std::uint8_t>(in[i])) << (8 * i);
  return v;
}
[[nodiscard]] std::uint64_t get_u64(const std::byte* in) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(std::to_integer<std::uint8_t>(in[i])) << (8 * i);
  return v;
}

// FNV-1a 64: simple, no table, catches the corruptions a file meets (not an adversary).
[[nodiscard]] std::uint64_t fnv1a(std::span<const std::byte> bytes, std::uint64_t h = 14695981039346656037ull) {
  for (const std::byte b : bytes) h = (h ^ std::to_integer<std::uint8_t>(b)) * 1099511628211ull;
  return h;
}

[[nodiscard]] std::uint64_t checksum(std::span<const std::byte> file) {
  return fnv1a(file.subspan(kHeaderSize), fnv1a(file.subspan(16, 16)));
}

}  // namespace

std::vector<std::byte> serialize(const Tree& tree) {
  const std::size_t n = tree.nodes.size();
  const std::size_t t = tree.triangle_order.size();
  std::vector<std::byte> out(kHeaderSize + n * kNodeSize + t * 4);
  std::memcpy(out.data(), kMagic.data(), kMagic.size());
  put_u32(&out[8], kTreeFormatVersion);
  put_u32(&out[12], static_cast<std::uint32_t>(kNodeSize));
  put_u64(&out[16], n);
  put_u64(&out[24], t);
  std::byte* p = out.data() + kHeaderSize;
  for (const Node& node : tree.nodes) {
    const auto put_f32 = [&p](float v) { put_u32(p, std::bit_cast<std::uint32_t>(v)), p += 4; };
    for (int i = 0; i < 3; ++i) put_f32(node.box.center[i]);
    for (int i = 0; i < 9; ++i) put_f32(node.box.axes(i % 3, i / 3));
    for (int i = 0; i < 3; ++i) put_f32(node.box.half_extents[i]);
    put_u32(p, node.first), p += 4;
    put_u32(p, node.count), p += 4;
  }
  for (const std::uint32_t i : tree.triangle_order) put_u32(p, i), p += 4;
  put_u64(&out[kChecksumOffset], checksum(out));
  return out;
}

Tree deserialize(std::span<const std::byte> bytes, const std::string& source) {
  const auto fail = [&source](const std::string& problem) { throw InputError(source + ": " + problem); };
  const std::size_t size = bytes.size();
  if (size == 0 || std::memcmp(bytes.data(), kMagic.data(), std::min(size, kMagic.size())) != 0)
    fail("not a tightbvh tree file (wrong magic)");
  if (size < kHeaderSize)
    fail("truncated: " + std::to_string(size) + " bytes, the header alone has " + std::to_string(kHeaderSize));
  const std::uint32_t version = get_u32(&bytes[8]);
  if (version == 1)
    fail("tree format version 1 (double-precision boxes, written before tightbvh stored float boxes) is no longer "
         "read: rebuild the tree from its mesh (tightbvh build)");
  if (version != kTreeFormatVersion)
    fail("unsupported tree format version " + std::to_string(version) + " (this build reads version " +
         std::to_string(kTreeFormatVersion) + ")");
  if (get_u32(&bytes[12]) != kNodeSize)
    fail("node size " + std::to_string(get_u32(&bytes[12])) + " instead of " + std::to_string(kNodeSize));
  const std::uint64_t n = get_u64(&bytes[16]);
  const std::uint64_t t = get_u64(&bytes[24]);
  // Bound the counts by the file size before any arithmetic that could overflow.
  const std::uint64_t payload = size - kHeaderSize;
  const bool fits = n <= payload / kNodeSize && t <= payload / 4;
  const std::uint64_t need = n * kNodeSize + t * 4;  // <= 2 * payload when `fits`: no overflow
  if (!fits || need != payload)
    fail(std::string(!fits || need > payload ? "truncated or corrupt sizes" : "trailing data") + ": the header says " +
         std::to_string(n) + " nodes and " + std::to_string(t) + " triangles, the file has " + std::to_string(size) +
         " bytes");
  if (n > std::numeric_limits<std::uint32_t>::max() || t > std::numeric_limits<std::uint32_t>::max())
    fail("more nodes or triangles than 32-bit indices allow");
  if (get_u64(&bytes[kChecksumOffset]) != checksum(bytes)) fail("checksum mismatch (the file is corrupted)");

  Tree tree;
  tree.nodes.resize(n);
  tree.triangle_order.resize(t);
  const std::byte* p = bytes.data() + kHeaderSize;
  for (Node& node : tree.nodes) {
    const auto get_f32 = [&p] {
      const float v = std::bit_cast<float>(get_u32(p));
      p += 4;
      return v;
    };
    for (int i = 0; i < 3; ++i) node.box.center[i] = get_f32();
    for (int i = 0; i < 9; ++i) node.box.axes(i % 3, i / 3) = get_f32();
    for (int i = 0; i < 3; ++i) node.box.half_extents[i] = get_f32();
    node.first = get_u32(p), p += 4;
    node.count = get_u32(p), p += 4;
  }
  for (std::uint32_t& i : tree.triangle_order) i = get_u32(p), p += 4;
  // A correct checksum only says the bytes are the ones written: check what they mean.
  if (const TreeCheck check = check_structure(tree); !check.ok()) fail("invalid tree structure: " + check.errors[0]);
  return tree;
}

void save_tree(const Tree& tree, std::ostream& out, const std::string& destination) {
  const std::vector<std::byte> bytes = serialize(tree);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) throw InputError(destination + ": write failed");
}

Tree load_tree(std::istream& in, const std::string& source) {
  // Read in chunks up to the end: the buffer is as large as the input, never as large as a field
  // inside it says.
  std::vector<std::byte> bytes;
  std::array<char, 1 << 16> chunk;
  while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0) {
    const auto* first = reinterpret_cast<const std::byte*>(chunk.data());
    bytes.insert(bytes.end(), first, first + in.gcount());
  }
  if (in.bad() || !in.eof()) throw InputError(source + ": read failed");
  return deserialize(bytes, source);
}

void save_tree(const Tree& tree, const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path.string() + ": cannot open for writing");
  save_tree(tree, out, path.string());
  out.close();
  if (!out) throw InputError(path.string() + ": write failed");
}

Tree load_tree(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open");
  return load_tree(in, path.string());
}

}  // namespace tightbvh
