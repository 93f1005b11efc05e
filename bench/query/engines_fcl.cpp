// FCL's own trees: BVHModel<OBB>, BVHModel<OBBRSS> and BVHModel<RSS> built by FCL (beginModel/endModel).
#include <string>

#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>

#include "fcl_adapter.hpp"

namespace tightbvh::bench {
namespace {

// FCL's own front tracking (BVHFrontList, fcl/narrowphase/detail/traversal/collision_node.h): the
// OBB mesh-mesh traversal node that fcl::collide builds internally, initialised per query and
// run with one front list per mode, kept across queries (as our -qc engines keep a QueryCache).
class FclFrontAdapter {
 public:
  using Obb = fcl::OBB<double>;
  FclFrontAdapter(FclModel<Obb> a, FclModel<Obb> b) : a_(std::move(a)), b_(std::move(b)) {
    first_.num_max_contacts = 1;
    first_.enable_contact = false;
    all_.num_max_contacts = std::numeric_limits<std::size_t>::max();
    all_.enable_contact = false;
  }

  [[nodiscard]] bool first_hit(const Pose& pose) {
    run(pose, first_, first_front_);
    return result_.isCollision();
  }
  void all_pairs(const Pose& pose, std::vector<Pair>& out) {
    run(pose, all_, all_front_);
    for (std::size_t i = 0; i < result_.numContacts(); ++i) {
      const auto& c = result_.getContact(i);
      out.emplace_back(std::uint32_t(c.b1), std::uint32_t(c.b2));
    }
  }
  [[nodiscard]] std::string stats() const {
    return "BVHFrontList sizes at the end: first_hit " + std::to_string(first_front_.size()) + ", all_pairs " +
           std::to_string(all_front_.size());
  }

 private:
  void run(const Pose& pose, const fcl::CollisionRequest<double>& request, fcl::detail::BVHFrontList& front) {
    result_.clear();
    fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
    tf.linear() = pose.rotation;
    tf.translation() = pose.translation;
    fcl::detail::MeshCollisionTraversalNodeOBB<double> node;
    // (const models and transforms select the OBB overload, which maps B into A's frame once)
    const fcl::BVHModel<Obb>& ma = *a_;
    const fcl::BVHModel<Obb>& mb = *b_;
    const fcl::Transform3<double>& ta = identity_;
    const fcl::Transform3<double>& tb = tf;
    fcl::detail::initialize(node, ma, ta, mb, tb, request, result_);
    fcl::detail::collide(&node, &front);
  }

  FclModel<Obb> a_, b_;
  fcl::Transform3<double> identity_ = fcl::Transform3<double>::Identity();
  fcl::CollisionRequest<double> first_, all_;
  fcl::CollisionResult<double> result_;
  fcl::detail::BVHFrontList first_front_, all_front_;
};

}  // namespace

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
      {"fcl-obb-front", true, true, "FCL's BVHFrontList kept across poses (coherent sequences)",
       [](const Input& in) {
         return prepare([&] { return std::make_unique<FclFrontAdapter>(fcl_model<Obb>(in.a), fcl_model<Obb>(in.b)); });
       },
       false, false, false, /*coherent=*/true},
      // PQP's volume, FCL's other distance BV; run in the distance mode only.
      {"fcl-rss", false, false, "distance mode only",
       [](const Input& in) {
         return prepare([&] { return std::make_unique<FclAdapter<Rss>>(fcl_model<Rss>(in.a), fcl_model<Rss>(in.b)); });
       },
       true},
  };
}

}  // namespace tightbvh::bench
