// FCL's own trees: BVHModel<OBB> and BVHModel<OBBRSS> built by FCL (beginModel/endModel).
#include "fcl_adapter.hpp"

namespace tightbvh::bench {

std::vector<EngineInfo> fcl_engines() {
  using Obb = fcl::OBB<double>;
  using ObbRss = fcl::OBBRSS<double>;
  return {
      {"fcl-obb", true, true, "",
       [](const Input& in) {
         return prepare([&] { return std::make_unique<FclAdapter<Obb>>(fcl_model<Obb>(in.a), fcl_model<Obb>(in.b)); });
       }},
      {"fcl-obbrss", true, true, "",
       [](const Input& in) {
         return prepare(
             [&] { return std::make_unique<FclAdapter<ObbRss>>(fcl_model<ObbRss>(in.a), fcl_model<ObbRss>(in.b)); });
       }},
  };
}

}  // namespace tightbvh::bench
