// QueryOptions::contacts (see contact_query.hpp and include/tightbvh/contact.hpp).
#include "contact_query.hpp"

#include <string>

#include "query_common.hpp"

#include "tightbvh/contact.hpp"
#include "tightbvh/error.hpp"

namespace tightbvh::query_detail {

void check_contacts(const char* what, const QueryOptions& options) {
  if (!options.contacts) return;
  if (options.mode != QueryMode::all_pairs)
    throw InputError(std::string(what) + ": contacts needs mode all_pairs (first_hit reports one pair only)");
  if (options.margin != 0.0)
    throw InputError(std::string(what) + ": contacts needs margin 0 (pairs within a margin need not touch), got " +
                     "margin " + std::to_string(options.margin));
}

void add_contacts(QueryResult& result, const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb) {
  const Pose rel = relative_pose(pa, pb);
  result.contacts.clear();
  result.contacts.reserve(result.pairs.size());
  result.curve_length = 0.0;
  for (const TrianglePair& pair : result.pairs) {
    std::array<Vec3, 3> b = mb.corners(pair.b);
    for (Vec3& p : b) p = map_point(rel, p);
    const Contact c = transformed(triangle_contact(ma.corners(pair.a), b), pa);
    result.curve_length += c.length();
    result.contacts.push_back(c);
  }
}

}  // namespace tightbvh::query_detail
