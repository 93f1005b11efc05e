// libFuzzer target for the tree loader (serialize.hpp). Built by scripts/fuzz-tree-loader with
// clang -fsanitize=fuzzer,address; not part of the GoogleTest binary.
//
// Each input is tried twice: as is (exercises the header, size and checksum checks), and with
// its checksum fixed up (so random bytes reach the structural checks behind the checksum).
// Properties: never crash, reject with InputError only, and anything accepted is a sound tree
// that serializes back to exactly the input bytes.
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "forge_checksum.hpp"
#include "tightbvh/mesh.hpp"
#include "tightbvh/serialize.hpp"
#include "tightbvh/validate_tree.hpp"

namespace {

void try_load(const std::vector<std::byte>& bytes) {
  try {
    const tightbvh::Tree tree = tightbvh::deserialize(bytes, "fuzz");
    if (!tightbvh::check_structure(tree).ok()) std::abort();
    if (tightbvh::serialize(tree) != bytes) std::abort();
  } catch (const tightbvh::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::byte> bytes(size);
  for (std::size_t i = 0; i < size; ++i) bytes[i] = std::byte{data[i]};
  try_load(bytes);
  if (bytes.size() >= 40) {
    tightbvh::test::fix_checksum(bytes);
    try_load(bytes);
  }
  return 0;
}
