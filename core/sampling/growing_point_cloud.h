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
// without weights weighing 1 (Section 4.1, per-point confidence). Each point of weight w > 0
// belongs to a weight class, the one whose bound U is the smallest power of two >= w; 278
// classes cover every finite float, denormals included, and points of weight 0 are in none. A
// weighted draw picks a class with probability count * U / sum(count * U) over the classes in
// use, a uniform member of it, and keeps that member with probability w / U, else tries again.
// The result is exactly proportional to weight, and since w / U > 1/2 a sample takes at most
// 2 tries in expectation however skewed the weights are (a point of weight 1 among a million of
// weight 0, or 1e30 among 1e-30), each try a pass over the classes in use and at most 3 random
// draws from a generator that one draw of the caller's seeds, so that every sample takes one
// draw of it and the sampler can load two samples ahead (PrefetchSample). A class keeps its
// members (index and weight) in chunks of geometrically growing size that never move, with a
// count published like the size: a weighted batch's points join their classes just after the
// size counts them. So a reader may see part of a batch whose Append has not returned (counted
// by size() but not yet all drawable); every point it can draw is fully stored, below size()
// and inside Bounds().
#ifndef NEURALMESH_CORE_SAMPLING_GROWING_POINT_CLOUD_H_
#define NEURALMESH_CORE_SAMPLING_GROWING_POINT_CLOUD_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
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
  // `max_points`: capacity, fixed for the object's life; values above 2^32 are lowered to
  // 2^32 (see max_points(); the weight classes number points with 32 bits). The chunk directory
  // costs 24 bytes per 65536 points of capacity (768 KiB at the default); point memory is only
  // allocated as points arrive, and so is a weight class's, about 8 to 16 bytes per member.
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

  // The checks of Append that concern the batch alone: INVALID_ARGUMENT for non-finite values
  // or weights/normals whose count does not match the positions (weights: finite, >= 0).
  static absl::Status ValidateBatch(absl::Span<const Vec3f> positions,
                                    absl::Span<const float> weights,
                                    absl::Span<const Vec3f> normals);

  // The checks of Append beyond ValidateBatch, without appending: with a batch that passed
  // ValidateBatch, OK when Append(batch) would succeed, as long as no other append comes first
  // (for a caller that must do something, such as storing the batch, between the check and
  // the append, and serialises its appends). O(1) but on the first batch (its weights).
  absl::Status CheckRoomFor(const PointCloud& batch) const;

  // The number of points visible to readers. Never decreases.
  size_t size() const { return size_.load(std::memory_order_acquire); }
  size_t max_points() const { return max_points_; }

  // Uniform over the points so far, or proportional to weight once any batch carried weights
  // (points without weights weigh 1). O(1) whatever the weights: one random draw when
  // weightless; when weighted, one draw that seeds at most 2 tries in expectation, each a pass
  // over the weight classes in use (at most 278) and at most 3 draws. A point that size() already
  // counts may not be drawable yet while its batch is being appended (see the top of this file).
  // Only called when !empty(); returns the origin otherwise.
  Vec3 Sample(Random& rng) const override { return Sample(rng, nullptr); }
  // As Sample(rng); `tries`, when not null, gets the number of tries the draw took (1 unless
  // weighted).
  Vec3 Sample(Random& rng, int* tries) const;
  // Starts loading the point that the next Sample(rng) returns. Weighted, it reads that
  // sample's first member, which the last call started loading, and starts loading its point
  // (or the next try's member) and the first member of the sample after it.
  void PrefetchSample(const Random& rng) const override;
  bool empty() const override { return size() == 0; }

  // The bounding box of all points so far. Takes a small lock that appends hold only while
  // extending the box, before the batch becomes visible, so it always contains every point a
  // concurrent Sample can return.
  BoundingBox Bounds() const override;

  // Everything so far (weights/normals filled with 1 / zero where a batch had none, only if any
  // batch had them). O(size()).
  PointCloud Copy() const;

 private:
  // Append's checks of room and weight: RESOURCE_EXHAUSTED when `n` more points would exceed
  // max_points after `old_size`; INVALID_ARGUMENT when they would be the first and weigh zero.
  absl::Status CheckRoom(size_t n, size_t old_size, bool weights_all_zero) const;

  static constexpr int kChunkBits = 16;
  static constexpr size_t kChunkSize = size_t{1} << kChunkBits;

  const Vec3f& PositionAt(size_t i) const {
    return position_chunks_[i >> kChunkBits][i & (kChunkSize - 1)];
  }
  float WeightAt(size_t i) const { return weight_chunks_[i >> kChunkBits][i & (kChunkSize - 1)]; }
  const Vec3f& NormalAt(size_t i) const {
    return normal_chunks_[i >> kChunkBits][i & (kChunkSize - 1)];
  }

  // Weight classes. Class k holds the points of weight w with U / 2 < w <= U, U = 2^(k +
  // kMinClassExponent): from the smallest denormal, 2^-149, to U = 2^128 > FLT_MAX.
  static constexpr int kMinClassExponent = -149;
  static constexpr int kMaxClassExponent = 128;
  static constexpr int kNumClasses = kMaxClassExponent - kMinClassExponent + 1;
  // A class's chunk j holds kFirstClassChunk << j members: 25 of them hold 2^32.
  static constexpr int kFirstClassChunkBits = 8;
  static constexpr size_t kFirstClassChunk = size_t{1} << kFirstClassChunkBits;
  static constexpr int kClassChunks = 25;

  // A member of a weight class: a point and its weight, side by side, so that a try of a
  // weighted draw reads one cache line before it knows whether it keeps the point.
  struct Member {
    uint32_t point;
    float weight;
  };

  // A class's members, in chunks written before the release store of the class's count that
  // makes their first member visible, and never changed afterwards, like the point chunks.
  struct WeightClass {
    // The chunk holding member `slot`, and the first slot of chunk j.
    static int ChunkOf(size_t slot) {
      return 63 - __builtin_clzll((slot >> kFirstClassChunkBits) + 1);
    }
    static size_t ChunkStart(int j) { return ((size_t{1} << j) - 1) << kFirstClassChunkBits; }

    const Member& MemberRef(size_t slot) const {
      const int j = ChunkOf(slot);
      return chunks[j][slot - ChunkStart(j)];
    }
    // Stores a member after the `written` ones; readers see it once the count covers it.
    void Add(uint32_t point, float weight);

    std::unique_ptr<Member[]> chunks[kClassChunks];
    size_t written = 0;  // Members stored; only the appending thread uses it.
  };

  // Writer-side helpers, called with append_mu_ held.
  template <typename T>
  static void Store(std::vector<std::unique_ptr<T[]>>& chunks, size_t begin,
                    absl::Span<const T> values);
  template <typename T>
  static void Fill(std::vector<std::unique_ptr<T[]>>& chunks, size_t begin, size_t end,
                   const T& value);
  // Adds points begin.. to their classes (weight 1 where `weights` is empty, else
  // weights[i - begin]; points of weight 0 to none) without publishing them.
  void Classify(size_t begin, size_t end, absl::Span<const float> weights);
  // Publishes the members added so far and the classes they opened.
  void PublishClasses();

  // The weight classes as one draw sees them: the counts of the listed classes and the running
  // sums of count * U, for Sample and PrefetchSample.
  struct ClassSnapshot {
    size_t classes = 0;
    size_t counts[kNumClasses];
    double cumulative[kNumClasses];  // Over list positions 0..p.
    double total() const { return classes == 0 ? 0.0 : cumulative[classes - 1]; }
  };
  void LoadClasses(ClassSnapshot* snapshot) const;
  // A list position p below snapshot.classes, with probability counts[p] * U_p / total (one
  // draw, none when there is one class).
  static size_t PickClass(Random& rng, const ClassSnapshot& snapshot);
  // One try's member: a class by PickClass, then a uniform member of it; `bound` gets the
  // class's U.
  const Member& PickMember(Random& tries, const ClassSnapshot& snapshot, double* bound) const;
  // Whether a try keeps `member`: with probability weight / bound (one draw unless they are
  // equal).
  static bool Keep(Random& tries, const Member& member, double bound);

  const size_t max_points_;

  // Directories of chunk pointers, sized once for max_points_. An entry is written (by the
  // appending thread, under append_mu_) before the first release store of size_ or of the
  // matching has_* flag that makes any of its points visible, and never changes afterwards, so
  // readers read entries without a lock.
  std::vector<std::unique_ptr<Vec3f[]>> position_chunks_;
  std::vector<std::unique_ptr<float[]>> weight_chunks_;
  std::vector<std::unique_ptr<Vec3f[]>> normal_chunks_;

  std::atomic<size_t> size_{0};
  // Set (release) once every visible point has a weight (normal) stored, and its class when
  // its weight is positive; before size_ grows over the first batch that carried them.
  std::atomic<bool> has_weights_{false};
  std::atomic<bool> has_normals_{false};

  // The weight classes by number k, allocated on first use; only the appending thread uses them.
  std::unique_ptr<WeightClass> classes_[kNumClasses];
  // The classes in use, in order of first use: at list position p, the class, its bound U (a
  // double: 2^128 is no float) and its count of members visible to readers, kept in arrays so
  // that a sample reads a few cache lines. Entries below class_list_size_ are written before
  // it is stored (release), and only counts change afterwards, each count growing by release
  // stores after its members are written; a listed class has members. Once has_weights_ is
  // set, a class at least is listed.
  const WeightClass* class_list_[kNumClasses] = {};
  double class_bounds_[kNumClasses] = {};
  std::atomic<size_t> class_counts_[kNumClasses] = {};
  std::atomic<size_t> class_list_size_{0};
  size_t class_list_written_ = 0;  // Only the appending thread uses it.

  // std::mutex rather than absl::Mutex: Debian's Abseil is not built with ThreadSanitizer,
  // which then cannot see the hand-offs of an absl::Mutex and reports false races; it does
  // understand std::mutex (pthreads).
  std::mutex append_mu_;  // Serialises Append.

  mutable std::mutex bounds_mu_;
  BoundingBox bounds_;  // Guarded by bounds_mu_.
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_SAMPLING_GROWING_POINT_CLOUD_H_
