// FCL's own trees: BVHModel<OBB>, BVHModel<OBBRSS> and BVHModel<RSS> built by FCL (beginModel/endModel).
#include "fcl_adapter.hpp"

namespace tightbvh::bench {

std::vector<EngineInfo> fcl_engines() {
  using Obb = fcl::OBB<double>;
  using ObbRss = fcl::OBBRSS<double>;
  using Rss = fcl::RSS<double>;
  return {
      {"fcl-obb", true, true, "",
       [](const Input& in) {
         return prepare([&] { return std::make_unique<FclAdapter<Obb>>(fcl_model<Obb>(in.a), fcl_model<Obb>(in.b)); });
       }},
      {"fcl-obbrss", true, true, "",
       [](const Input& in) {
         return prepare(
             [&] { return std::make_unique<FclAdapter<ObbRss>>(fcl_model<ObbRss>(in.a), fcl_model<ObbRss>(in.b)); });
       },
       true},
      // PQP's volume, FCL's other distance BV; run in the distance mode only.
      {"fcl-rss", false, false, "distance mode only",
       [](const Input& in) {
         return prepare([&] { return std::make_unique<FclAdapter<Rss>>(fcl_model<Rss>(in.a), fcl_model<Rss>(in.b)); });
       },
       true},
  };
}

}  // namespace tightbvh::bench
