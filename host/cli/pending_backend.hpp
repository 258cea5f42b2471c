#pragma once
// A feature backend still being set up on another thread. The CLI starts the OpenCL set-up
// (about 0.1 s on PoCL) before it reads the scan and hands this to the pipeline, which waits
// for the backend only when a stage first calls it: the read, and the robust method's voxels,
// run in the meantime.

#include <functional>
#include <future>
#include <groovetrace/features.hpp>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace {

/// Forwards every call to the backend `pending` delivers, waiting for it on the first call;
/// `on_ready` runs once, then. An error of the set-up (OpenClError, UsageError) is thrown by
/// that first call.
class PendingBackend final : public FeatureBackend {
 public:
  PendingBackend(std::future<std::unique_ptr<FeatureBackend>> pending,
                 std::function<void(FeatureBackend&)> on_ready)
      : pending_(std::move(pending)), on_ready_(std::move(on_ready)) {}

  std::string name() const override { return ready().name(); }
  std::string device() const override { return ready().device(); }
  std::string warning() const override { return ready().warning(); }
  Cloud smooth(const Cloud& cloud, const SmoothParams& params) override {
    return ready().smooth(cloud, params);
  }
  Normals normals(const Cloud& cloud, float radius, int min_neighbors) override {
    return ready().normals(cloud, radius, min_neighbors);
  }
  std::vector<float> descriptor(const Cloud& cloud, const Normals& normals, float radius,
                                const Eigen::Vector3f& u_b) override {
    return ready().descriptor(cloud, normals, radius, u_b);
  }
  FeatureSet features(const Cloud& cloud, float radius, int min_neighbors) override {
    return ready().features(cloud, radius, min_neighbors);
  }
  CreaseMeasure crease(const Cloud& cloud, const CreaseParams& params) override {
    return ready().crease(cloud, params);
  }

 private:
  FeatureBackend& ready() const {
    if (!backend_) {
      backend_ = pending_.get();
      if (on_ready_) on_ready_(*backend_);
    }
    return *backend_;
  }

  mutable std::future<std::unique_ptr<FeatureBackend>> pending_;
  std::function<void(FeatureBackend&)> on_ready_;
  mutable std::unique_ptr<FeatureBackend> backend_;
};

}  // namespace groovetrace
