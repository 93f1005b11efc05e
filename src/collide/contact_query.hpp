#pragma once
// QueryOptions::contacts: the contact geometry of the pairs a collide query reported, computed
// after the traversal (internal to src/collide).
#include "tightbvh/collide.hpp"

namespace tightbvh::query_detail {

// Throws InputError unless options.contacts is usable: all_pairs and no margin. `what` names the
// query ("collide").
void check_contacts(const char* what, const QueryOptions& options);

// Fills result.contacts (parallel to result.pairs, world frame) and result.curve_length. The
// triangle pairs are taken in A's mesh frame with B's corners mapped by relative_pose(pa, pb), as
// the queries test them, and the contacts mapped to the world by pa.
void add_contacts(QueryResult& result, const Mesh& ma, const Pose& pa, const Mesh& mb, const Pose& pb);

}  // namespace tightbvh::query_detail
