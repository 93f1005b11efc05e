#include "tightbvh/tree_obj.hpp"

#include <fstream>
#include <sstream>

#include "tightbvh/error.hpp"
#include "tightbvh/tree_walk.hpp"

namespace tightbvh {

std::size_t write_boxes_obj(const Tree& tree, std::size_t level, std::ostream& out) {
  const auto precision = out.precision(17);
  out << "# tightbvh: boxes of tree level " << level << "\n";
  std::size_t boxes = 0;
  for_each_node(tree, [&](const NodeVisit& v) {
    if (v.depth < level) return true;
    // Obb::corners: bit 0 -> +axis 0, bit 1 -> +axis 1, bit 2 -> +axis 2.
    for (const Vec3& c : v.node.box.obb().corners()) out << "v " << c.x() << ' ' << c.y() << ' ' << c.z() << '\n';
    const std::size_t base = 8 * boxes + 1;
    for (int a = 0; a < 8; ++a)
      for (const int bit : {1, 2, 4})
        if (!(a & bit)) out << "l " << base + a << ' ' << base + (a | bit) << '\n';
    ++boxes;
    return false;  // nothing below the level is written
  });
  out.precision(precision);
  return boxes;
}

std::size_t write_boxes_obj(const Tree& tree, std::size_t level, const std::filesystem::path& path) {
  // Built in memory first: a failed run leaves no half-written file behind the open.
  std::ostringstream text;
  const std::size_t boxes = write_boxes_obj(tree, level, text);
  std::ofstream file(path);
  if (!file) throw InputError(path.string() + ": cannot open for writing");
  file << text.str();
  if (!file.flush()) throw InputError(path.string() + ": write failed");
  return boxes;
}

}  // namespace tightbvh
