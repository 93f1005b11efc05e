#pragma once
// FCL engine adapter: fcl::collide on two BVHModels, with num_max_contacts 1 (first_hit) or
// unlimited (all_pairs) and enable_contact off, as FCL users query triangle pairs; fcl::distance
// with the default DistanceRequest (exact: rel_err = abs_err = 0, no nearest points) for the
// BV types FCL supports it on (RSS, OBBRSS).
#include <algorithm>
#include <limits>
#include <memory>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include "bench.hpp"

namespace tightbvh::bench {

template <class BV>
using FclModel = std::shared_ptr<fcl::BVHModel<BV>>;

// FCL's own tree (its default splitter and fitter), as any FCL user builds it.
template <class BV>
[[nodiscard]] FclModel<BV> fcl_model(const Mesh& mesh) {
  auto model = std::make_shared<fcl::BVHModel<BV>>();
  std::vector<fcl::Vector3<double>> vertices(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  model->beginModel(int(triangles.size()), int(vertices.size()));
  model->addSubModel(vertices, triangles);
  model->endModel();
  model->computeLocalAABB();
  return model;
}

template <class BV>
class FclAdapter {
 public:
  FclAdapter(FclModel<BV> a, FclModel<BV> b) : a_(std::move(a)), b_(std::move(b)) {
    first_.num_max_contacts = 1;
    first_.enable_contact = false;
    all_.num_max_contacts = std::numeric_limits<std::size_t>::max();
    all_.enable_contact = false;
  }

  [[nodiscard]] bool first_hit(const Pose& pose) {
    result_.clear();
    fcl::collide(a_.get(), identity_, b_.get(), transform(pose), first_, result_);
    return result_.isCollision();
  }

  void all_pairs(const Pose& pose, std::vector<Pair>& out) {
    result_.clear();
    fcl::collide(a_.get(), identity_, b_.get(), transform(pose), all_, result_);
    for (std::size_t i = 0; i < result_.numContacts(); ++i) {
      const auto& c = result_.getContact(i);
      out.emplace_back(std::uint32_t(c.b1), std::uint32_t(c.b2));
    }
  }

  [[nodiscard]] double distance(const Pose& pose) {
    distance_result_.clear();
    fcl::distance(a_.get(), identity_, b_.get(), transform(pose), distance_request_, distance_result_);
    return std::max(0.0, distance_result_.min_distance);  // FCL reports touching meshes as <= 0
  }

 private:
  [[nodiscard]] static fcl::Transform3<double> transform(const Pose& pose) {
    fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
    tf.linear() = pose.rotation;
    tf.translation() = pose.translation;
    return tf;
  }

  FclModel<BV> a_, b_;
  fcl::Transform3<double> identity_ = fcl::Transform3<double>::Identity();
  fcl::CollisionRequest<double> first_, all_;
  fcl::CollisionResult<double> result_;
  fcl::DistanceRequest<double> distance_request_;
  fcl::DistanceResult<double> distance_result_;
};

}  // namespace tightbvh::bench
