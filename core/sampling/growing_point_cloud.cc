#include "core/sampling/growing_point_cloud.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

constexpr size_t kLargestMaxPoints = size_t{1} << 34;

bool IsFinite(const Vec3f& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace

GrowingPointCloud::GrowingPointCloud(size_t max_points)
    : max_points_(std::min(max_points, kLargestMaxPoints)) {
  const size_t chunks = (max_points_ + kChunkSize - 1) / kChunkSize;
  position_chunks_.resize(chunks);
  weight_chunks_.resize(chunks);
  normal_chunks_.resize(chunks);
}

template <typename T>
void GrowingPointCloud::Store(std::vector<std::unique_ptr<T[]>>& chunks, size_t begin,
                              absl::Span<const T> values) {
  size_t done = 0;
  while (done < values.size()) {
    const size_t i = begin + done;
    std::unique_ptr<T[]>& chunk = chunks[i >> kChunkBits];
    if (chunk == nullptr) chunk.reset(new T[kChunkSize]);
    const size_t offset = i & (kChunkSize - 1);
    const size_t count = std::min(kChunkSize - offset, values.size() - done);
    std::copy_n(values.data() + done, count, chunk.get() + offset);
    done += count;
  }
}

template <typename T>
void GrowingPointCloud::Fill(std::vector<std::unique_ptr<T[]>>& chunks, size_t begin, size_t end,
                             const T& value) {
  for (size_t i = begin; i < end;) {
    std::unique_ptr<T[]>& chunk = chunks[i >> kChunkBits];
    if (chunk == nullptr) chunk.reset(new T[kChunkSize]);
    const size_t offset = i & (kChunkSize - 1);
    const size_t count = std::min(kChunkSize - offset, end - i);
    std::fill_n(chunk.get() + offset, count, value);
    i += count;
  }
}

absl::Status GrowingPointCloud::Append(absl::Span<const Vec3f> positions,
                                       absl::Span<const float> weights,
                                       absl::Span<const Vec3f> normals) {
  const size_t n = positions.size();
  if (!weights.empty() && weights.size() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("the batch has ", weights.size(), " weights for ", n, " points"));
  }
  if (!normals.empty() && normals.size() != n) {
    return absl::InvalidArgumentError(
        absl::StrCat("the batch has ", normals.size(), " normals for ", n, " points"));
  }
  BoundingBox batch_bounds;
  for (size_t i = 0; i < n; ++i) {
    if (!IsFinite(positions[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("point ", i, " of the batch has a non-finite coordinate"));
    }
    batch_bounds.Extend(Vec3(positions[i]));
  }
  float batch_max_weight = 0.0f;
  for (size_t i = 0; i < weights.size(); ++i) {
    if (!std::isfinite(weights[i]) || weights[i] < 0) {
      return absl::InvalidArgumentError(absl::StrCat("weight ", i, " of the batch is ", weights[i],
                                                     "; weights must be finite and >= 0"));
    }
    batch_max_weight = std::max(batch_max_weight, weights[i]);
  }
  for (size_t i = 0; i < normals.size(); ++i) {
    if (!IsFinite(normals[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("normal ", i, " of the batch has a non-finite component"));
    }
  }
  if (n == 0) return absl::OkStatus();

  std::lock_guard<std::mutex> lock(append_mu_);
  // Only this thread changes size_, so a relaxed load sees the latest value.
  const size_t old_size = size_.load(std::memory_order_relaxed);
  if (n > max_points_ - old_size) {
    return absl::ResourceExhaustedError(absl::StrCat("appending ", n, " points to ", old_size,
                                                     " would exceed the capacity of ", max_points_,
                                                     " points"));
  }
  if (old_size == 0 && !weights.empty() && batch_max_weight == 0.0f) {
    return absl::InvalidArgumentError(
        "every weight of the first batch is zero: there would be nothing to sample");
  }

  // Earlier points weigh 1 and have a zero normal; they get them before the flag that lets
  // readers look for them.
  if (!weights.empty() && !has_weights_.load(std::memory_order_relaxed)) {
    Fill(weight_chunks_, 0, old_size, 1.0f);
    has_weights_.store(true, std::memory_order_release);
  }
  if (!normals.empty() && !has_normals_.load(std::memory_order_relaxed)) {
    Fill(normal_chunks_, 0, old_size, Vec3f(0.0f, 0.0f, 0.0f));
    has_normals_.store(true, std::memory_order_release);
  }

  Store(position_chunks_, old_size, positions);
  float max_weight = max_weight_.load(std::memory_order_relaxed);
  if (has_weights_.load(std::memory_order_relaxed)) {
    if (weights.empty()) {
      Fill(weight_chunks_, old_size, old_size + n, 1.0f);
      max_weight = std::max(max_weight, 1.0f);
    } else {
      Store(weight_chunks_, old_size, weights);
      max_weight = std::max(max_weight, batch_max_weight);
    }
  } else {
    max_weight = std::max(max_weight, 1.0f);
  }
  if (has_normals_.load(std::memory_order_relaxed)) {
    if (normals.empty()) {
      Fill(normal_chunks_, old_size, old_size + n, Vec3f(0.0f, 0.0f, 0.0f));
    } else {
      Store(normal_chunks_, old_size, normals);
    }
  }
  max_weight_.store(max_weight, std::memory_order_release);
  {
    std::lock_guard<std::mutex> bounds_lock(bounds_mu_);
    bounds_.Extend(batch_bounds);
  }
  size_.store(old_size + n, std::memory_order_release);
  return absl::OkStatus();
}

absl::Status GrowingPointCloud::Append(const PointCloud& batch) {
  return Append(batch.positions, batch.weights, batch.normals);
}

Vec3 GrowingPointCloud::Sample(Random& rng) const {
  const size_t n = size_.load(std::memory_order_acquire);
  if (n == 0) return Vec3(0.0, 0.0, 0.0);
  if (!has_weights_.load(std::memory_order_acquire)) return Vec3(PositionAt(rng.NextIndex(n)));
  // Loaded after size_, so it bounds the weight of every point below n; a larger value from a
  // batch still being written only costs extra rejections. Constant for the whole draw.
  const double max_weight = max_weight_.load(std::memory_order_acquire);
  while (true) {
    const size_t i = rng.NextIndex(n);
    if (rng.NextDouble() * max_weight < WeightAt(i)) return Vec3(PositionAt(i));
  }
}

BoundingBox GrowingPointCloud::Bounds() const {
  std::lock_guard<std::mutex> lock(bounds_mu_);
  return bounds_;
}

PointCloud GrowingPointCloud::Copy() const {
  const size_t n = size_.load(std::memory_order_acquire);
  const bool weighted = has_weights_.load(std::memory_order_acquire);
  const bool with_normals = has_normals_.load(std::memory_order_acquire);
  PointCloud cloud;
  cloud.positions.reserve(n);
  for (size_t i = 0; i < n; ++i) cloud.positions.push_back(PositionAt(i));
  if (weighted) {
    cloud.weights.reserve(n);
    for (size_t i = 0; i < n; ++i) cloud.weights.push_back(WeightAt(i));
  }
  if (with_normals) {
    cloud.normals.reserve(n);
    for (size_t i = 0; i < n; ++i) cloud.normals.push_back(NormalAt(i));
  }
  return cloud;
}

}  // namespace neuralmesh
