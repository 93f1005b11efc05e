#include "tightbvh/serialize.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "build_test_util.hpp"
#include "forge_checksum.hpp"
#include "tightbvh/validate_tree.hpp"

namespace tightbvh {
namespace {

Tree elephant_tree(const Mesh& mesh) {
  BuildOptions options;
  options.fitter = FitMethod::pca;
  options.leaf_size = 2;
  return build(mesh, options);
}

Mesh elephant() { return load_mesh(test::source_dir() / "meshes/elephant.off"); }

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("tightbvh_serialize_test_" + name);
}

void write_bytes(const std::filesystem::path& path, const std::vector<std::byte>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void put_u32(std::vector<std::byte>& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = std::byte((v >> (8 * i)) & 0xff);
}
void put_u64(std::vector<std::byte>& bytes, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) bytes[at + i] = std::byte((v >> (8 * i)) & 0xff);
}

// Expects deserialize to throw an InputError whose message names the source and contains `what`.
void expect_rejected(const std::vector<std::byte>& bytes, const std::string& what) {
  try {
    (void)deserialize(bytes, "test.tree");
    ADD_FAILURE() << "accepted, expected: " << what;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("test.tree: ", 0), 0u) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

TEST(Serialize, RoundTripIsExact) {
  const Mesh mesh = elephant();
  const Tree tree = elephant_tree(mesh);
  const auto path = temp_file("roundtrip.tree");
  save_tree(tree, path);
  const Tree loaded = load_tree(path);
  ASSERT_EQ(loaded.nodes.size(), tree.nodes.size());
  EXPECT_EQ(std::memcmp(loaded.nodes.data(), tree.nodes.data(), tree.nodes.size() * sizeof(Node)), 0);
  EXPECT_EQ(loaded.triangle_order, tree.triangle_order);
  EXPECT_TRUE(validate(loaded, mesh).ok());
  EXPECT_EQ(std::filesystem::file_size(path), 40 + tree.nodes.size() * 68 + tree.triangle_order.size() * 4);
  std::filesystem::remove(path);
}

TEST(Serialize, SingleNodeTree) {
  Mesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  BuildOptions options;
  options.fitter = FitMethod::aabb;
  const Tree tree = build(one, options);
  const Tree loaded = deserialize(serialize(tree));
  EXPECT_EQ(loaded.nodes.size(), 1u);
  EXPECT_TRUE(validate(loaded, one).ok());
}

TEST(Serialize, RejectsWrongMagicVersionAndSizes) {
  const auto good = serialize(elephant_tree(elephant()));
  expect_rejected({}, "wrong magic");
  std::vector<std::byte> text(good.size(), std::byte{'x'});
  expect_rejected(text, "wrong magic");
  expect_rejected(std::vector<std::byte>(good.begin(), good.begin() + 5), "truncated");  // a prefix of the magic
  auto version = good;
  put_u32(version, 8, 3);
  expect_rejected(version, "unsupported tree format version 3");
  put_u32(version, 8, 1);  // version 1, the double-box format: the message says what to do
  expect_rejected(version, "version 1 (double-precision boxes");
  expect_rejected(version, "rebuild the tree");
  expect_rejected(std::vector<std::byte>(good.begin(), good.begin() + 20), "truncated");
  expect_rejected(std::vector<std::byte>(good.begin(), good.end() - 1), "truncated");
  auto trailing = good;
  trailing.push_back(std::byte{0});
  expect_rejected(trailing, "trailing data");
  auto huge = good;
  put_u64(huge, 16, std::uint64_t{1} << 60);  // nodes: must not allocate 2^67 bytes
  expect_rejected(huge, "corrupt sizes");
  put_u64(huge, 16, ~std::uint64_t{0});
  expect_rejected(huge, "corrupt sizes");
  auto huge_triangles = good;
  put_u64(huge_triangles, 24, std::uint64_t{1} << 62);
  expect_rejected(huge_triangles, "corrupt sizes");
}

TEST(Serialize, RejectsCorruptedBytes) {
  const auto good = serialize(elephant_tree(elephant()));
  for (const std::size_t at : {std::size_t{20}, std::size_t{40}, good.size() / 2, good.size() - 1}) {
    auto bad = good;
    bad[at] ^= std::byte{0x10};
    if (at == 20) {
      expect_rejected(bad, "corrupt sizes");  // the node count changed: caught by the size check
    } else {
      expect_rejected(bad, "checksum mismatch");
    }
  }
}

TEST(Serialize, RejectsBadStructureWithValidChecksum) {
  const Tree tree = elephant_tree(elephant());
  const auto good = serialize(tree);
  const std::size_t root_first = 40 + 60;  // node 0: 15 floats, then first, count
  auto child = good;
  put_u32(child, root_first, static_cast<std::uint32_t>(tree.nodes.size()));  // children out of range
  test::fix_checksum(child);
  expect_rejected(child, "invalid tree structure: node 0: children");
  auto cycle = good;
  put_u32(cycle, root_first, 0);  // root's own child
  test::fix_checksum(cycle);
  expect_rejected(cycle, "invalid tree structure");
  auto order = good;
  put_u32(order, order.size() - 4, 1u << 30);  // triangle index out of range
  test::fix_checksum(order);
  expect_rejected(order, "out of range");
  auto nan = good;
  put_u32(nan, 40, 0x7fc00000u);  // root center x = NaN
  test::fix_checksum(nan);
  expect_rejected(nan, "non-finite");
}

TEST(Serialize, LoadNamesTheFile) {
  const auto path = temp_file("truncated.tree");
  auto bytes = serialize(elephant_tree(elephant()));
  bytes.resize(bytes.size() / 3);
  write_bytes(path, bytes);
  try {
    (void)load_tree(path);
    ADD_FAILURE() << "truncated file accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ": truncated"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
  EXPECT_THROW((void)load_tree(temp_file("does-not-exist.tree")), InputError);
}

TEST(Serialize, EveryTruncationIsRejected) {
  // Small tree: every prefix, never a crash (also under ASan in the lead's run).
  const Mesh soup = test::random_soup(5, 3);
  BuildOptions options;
  options.fitter = FitMethod::aabb;
  const auto good = serialize(build(soup, options));
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_THROW((void)deserialize(std::vector<std::byte>(good.begin(), good.begin() + n)), InputError) << n;
  EXPECT_NO_THROW((void)deserialize(good));
}

std::vector<std::byte> bytes_of(const std::string& s) {
  const auto* first = reinterpret_cast<const std::byte*>(s.data());
  return {first, first + s.size()};
}

std::string string_of(const std::vector<std::byte>& bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

TEST(Serialize, StreamFormIsTheFileForm) {
  const Mesh mesh = elephant();
  const Tree tree = elephant_tree(mesh);
  const auto path = temp_file("stream.tree");
  save_tree(tree, path);
  std::ifstream file(path, std::ios::binary);
  const std::string file_bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  std::ostringstream out;
  save_tree(tree, out);
  EXPECT_EQ(out.str(), file_bytes);  // byte for byte
  EXPECT_EQ(bytes_of(out.str()), serialize(tree));
  std::istringstream in(out.str());
  const Tree loaded = load_tree(in);
  ASSERT_EQ(loaded.nodes.size(), tree.nodes.size());
  EXPECT_EQ(std::memcmp(loaded.nodes.data(), tree.nodes.data(), tree.nodes.size() * sizeof(Node)), 0);
  EXPECT_EQ(loaded.triangle_order, tree.triangle_order);
  EXPECT_EQ(serialize(loaded), serialize(tree));
  std::filesystem::remove(path);
}

TEST(Serialize, StreamRejectsTruncatedAndCorruptBytes) {
  const std::string good = string_of(serialize(elephant_tree(elephant())));
  const auto rejected = [](const std::string& bytes, const std::string& what) {
    std::istringstream in(bytes);
    try {
      (void)load_tree(in, "pickle");
      ADD_FAILURE() << "accepted, expected: " << what;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("pickle: ", 0), 0u) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message;
    }
  };
  rejected("", "wrong magic");
  rejected(good.substr(0, 30), "truncated");
  rejected(good.substr(0, good.size() - 3), "truncated");
  rejected(good + "x", "trailing data");
  std::string flipped = good;
  flipped[good.size() / 2] = static_cast<char>(flipped[good.size() / 2] ^ 0x10);
  rejected(flipped, "checksum mismatch");
  std::istringstream failed(good);
  failed.setstate(std::ios::badbit);  // a stream that cannot be read
  EXPECT_THROW((void)load_tree(failed, "pickle"), InputError);
}

TEST(Serialize, StreamWriteFailureIsAnInputError) {
  std::ostringstream out;
  out.setstate(std::ios::badbit);
  EXPECT_THROW(save_tree(elephant_tree(elephant()), out, "sink"), InputError);
}

}  // namespace
}  // namespace tightbvh
