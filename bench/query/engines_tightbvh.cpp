// Our engines (tightbvh-*), our trees inside FCL (fcl-export-*), and the reference.
#include <sstream>

#include "fcl_adapter.hpp"

#if __has_include("tightbvh/collide.hpp") && __has_include("tightbvh/build.hpp")
#define TIGHTBVH_BENCH_HAVE_COLLIDE 1
#include "tightbvh/build.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/fcl_export.hpp"
#endif

namespace tightbvh::bench {

#ifndef TIGHTBVH_BENCH_HAVE_COLLIDE
// Until the tree builder and collide land: FCL's OBB trees stand in as the reference.
struct Reference::Impl {
  FclAdapter<fcl::OBB<double>> fcl;
};
Reference::Reference(const Input& in)
    : impl_(new Impl{FclAdapter<fcl::OBB<double>>(fcl_model<fcl::OBB<double>>(in.a),
                                                  fcl_model<fcl::OBB<double>>(in.b))}) {}
Reference::~Reference() = default;
bool Reference::collides(const Pose& p) const { return impl_->fcl.first_hit(p); }
std::vector<Pair> Reference::pairs(const Pose& p) const {
  std::vector<Pair> out;
  impl_->fcl.all_pairs(p, out);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}
std::string Reference::description() const { return "TEMPORARY: fcl-obb all pairs (tightbvh collide not merged)"; }
std::vector<EngineInfo> tightbvh_engines() { return {}; }
#endif

}  // namespace tightbvh::bench
