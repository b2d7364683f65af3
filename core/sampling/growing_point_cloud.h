// A point cloud that grows while it is sampled: the server streams batches in on one thread
// while the learner samples on another (Section 2.1: the target space P is only ever touched
// through one sample at a time, so it may keep growing during learning).
//
// Storage is a directory of fixed-size chunks (65536 points each) sized for max_points up
// front; chunks are allocated on demand and never move, so readers index them without a lock.
// Appends serialise on a mutex, write the batch into the chunks and then publish the new size
// with a release store; readers load the size with acquire and only touch points below it.
//
// Sampling is uniform over the points appended so far until the first batch with weights
// arrives; from then on point i is drawn with probability w_i / sum(w), points of batches
// without weights weighing 1 (Section 4.1, per-point confidence). The weighted draw is a
// rejection against the running maximum weight: a uniform index i is kept with probability
// w_i / w_max, so a sample costs w_max / mean(w) draws in expectation, independent of the
// number of points (1 when all weights are equal, 10 when one in ten points weighs 10 and the
// rest almost nothing).
#ifndef NEURALMESH_CORE_SAMPLING_GROWING_POINT_CLOUD_H_
#define NEURALMESH_CORE_SAMPLING_GROWING_POINT_CLOUD_H_

#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "core/bounding_box.h"
#include "core/mesh.h"
#include "core/point_cloud.h"
#include "core/random.h"
#include "core/sampling/sampler.h"

namespace neuralmesh {

class GrowingPointCloud : public Sampler {
 public:
  // `max_points`: capacity, fixed for the object's life; values above 2^34 are lowered to
  // 2^34 (see max_points()). The chunk directory costs 24 bytes per 65536 points of capacity
  // (768 KiB at the default); point memory is only allocated as points arrive.
  explicit GrowingPointCloud(size_t max_points = size_t{1} << 31);

  GrowingPointCloud(const GrowingPointCloud&) = delete;
  GrowingPointCloud& operator=(const GrowingPointCloud&) = delete;

  // Appends a batch atomically (all or nothing). Thread-safe with respect to concurrent Sample/
  // size/Bounds/Copy calls and other Append calls (appends serialise on a mutex; readers never
  // block on it). INVALID_ARGUMENT for non-finite values or weights/normals whose count does not
  // match the positions (weights: finite, >= 0), and when every point so far, this batch
  // included, would weigh zero (nothing could be sampled); RESOURCE_EXHAUSTED when the batch
  // would exceed max_points. On error nothing is appended. O(batch size), plus a one-time
  // O(size()) when the first batch with weights (or normals) arrives and the earlier points get
  // weight 1 (normal zero).
  absl::Status Append(absl::Span<const Vec3f> positions, absl::Span<const float> weights = {},
                      absl::Span<const Vec3f> normals = {});
  absl::Status Append(const PointCloud& batch);

  // The number of points visible to readers. Never decreases.
  size_t size() const { return size_.load(std::memory_order_acquire); }
  size_t max_points() const { return max_points_; }

  // Uniform over the points so far, or proportional to weight once any batch carried weights
  // (points without weights weigh 1). Expected O(w_max / mean(w)) draws, O(1) when weightless.
  // Only called when !empty(); returns the origin otherwise.
  Vec3 Sample(Random& rng) const override;
  bool empty() const override { return size() == 0; }

  // The bounding box of all points so far. Takes a small lock that appends hold only while
  // extending the box, before the batch becomes visible, so it always contains every point a
  // concurrent Sample can return.
  BoundingBox Bounds() const override;

  // Everything so far (weights/normals filled with 1 / zero where a batch had none, only if any
  // batch had them). O(size()).
  PointCloud Copy() const;

 private:
  static constexpr int kChunkBits = 16;
  static constexpr size_t kChunkSize = size_t{1} << kChunkBits;

  const Vec3f& PositionAt(size_t i) const {
    return position_chunks_[i >> kChunkBits][i & (kChunkSize - 1)];
  }
  float WeightAt(size_t i) const { return weight_chunks_[i >> kChunkBits][i & (kChunkSize - 1)]; }
  const Vec3f& NormalAt(size_t i) const {
    return normal_chunks_[i >> kChunkBits][i & (kChunkSize - 1)];
  }

  // Writer-side helpers, called with append_mu_ held.
  template <typename T>
  static void Store(std::vector<std::unique_ptr<T[]>>& chunks, size_t begin,
                    absl::Span<const T> values);
  template <typename T>
  static void Fill(std::vector<std::unique_ptr<T[]>>& chunks, size_t begin, size_t end,
                   const T& value);

  const size_t max_points_;

  // Directories of chunk pointers, sized once for max_points_. An entry is written (by the
  // appending thread, under append_mu_) before the first release store of size_ or of the
  // matching has_* flag that makes any of its points visible, and never changes afterwards, so
  // readers read entries without a lock.
  std::vector<std::unique_ptr<Vec3f[]>> position_chunks_;
  std::vector<std::unique_ptr<float[]>> weight_chunks_;
  std::vector<std::unique_ptr<Vec3f[]>> normal_chunks_;

  std::atomic<size_t> size_{0};
  // Set (release) once every visible point has a weight (normal) stored; before size_ grows
  // over the first batch that carried them.
  std::atomic<bool> has_weights_{false};
  std::atomic<bool> has_normals_{false};
  // The largest weight stored so far, raised before size_ publishes the points that carry it.
  std::atomic<float> max_weight_{0.0f};

  // std::mutex rather than absl::Mutex: Debian's Abseil is not built with ThreadSanitizer,
  // which then cannot see the hand-offs of an absl::Mutex and reports false races; it does
  // understand std::mutex (pthreads).
  std::mutex append_mu_;  // Serialises Append.

  mutable std::mutex bounds_mu_;
  BoundingBox bounds_;  // Guarded by bounds_mu_.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_GROWING_POINT_CLOUD_H_
