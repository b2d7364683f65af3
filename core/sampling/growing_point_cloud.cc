#include "core/sampling/growing_point_cloud.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/status_macros.h"

namespace neuralmesh {
namespace {

constexpr size_t kLargestMaxPoints = size_t{1} << 32;

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

void GrowingPointCloud::WeightClass::Add(uint32_t point, float weight) {
  const int j = ChunkOf(written);
  if (chunks[j] == nullptr) chunks[j].reset(new Member[kFirstClassChunk << j]);
  chunks[j][written - ChunkStart(j)] = Member{point, weight};
  ++written;
}

void GrowingPointCloud::Classify(size_t begin, size_t end, absl::Span<const float> weights) {
  for (size_t i = begin; i < end; ++i) {
    const float w = weights.empty() ? 1.0f : weights[i - begin];
    if (w == 0.0f) continue;
    // U = 2^e, or 2^(e-1) when w = 2^(e-1) exactly: the smallest power of two >= w.
    int e;
    if (std::frexp(w, &e) == 0.5f) --e;
    std::unique_ptr<WeightClass>& c = classes_[e - kMinClassExponent];
    if (c == nullptr) {
      c = std::make_unique<WeightClass>();
      class_list_[class_list_written_] = c.get();
      class_bounds_[class_list_written_] = std::ldexp(1.0, e);
      ++class_list_written_;
    }
    c->Add(static_cast<uint32_t>(i), w);
  }
}

void GrowingPointCloud::PublishClasses() {
  for (size_t p = 0; p < class_list_written_; ++p) {
    const size_t written = class_list_[p]->written;
    if (class_counts_[p].load(std::memory_order_relaxed) != written) {
      class_counts_[p].store(written, std::memory_order_release);
    }
  }
  // After the counts: a reader that sees a class listed sees its first members.
  class_list_size_.store(class_list_written_, std::memory_order_release);
}

absl::Status GrowingPointCloud::ValidateBatch(absl::Span<const Vec3f> positions,
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
  for (size_t i = 0; i < n; ++i) {
    if (!IsFinite(positions[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("point ", i, " of the batch has a non-finite coordinate"));
    }
  }
  for (size_t i = 0; i < weights.size(); ++i) {
    if (!std::isfinite(weights[i]) || weights[i] < 0) {
      return absl::InvalidArgumentError(absl::StrCat("weight ", i, " of the batch is ", weights[i],
                                                     "; weights must be finite and >= 0"));
    }
  }
  for (size_t i = 0; i < normals.size(); ++i) {
    if (!IsFinite(normals[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("normal ", i, " of the batch has a non-finite component"));
    }
  }
  return absl::OkStatus();
}

absl::Status GrowingPointCloud::Append(absl::Span<const Vec3f> positions,
                                       absl::Span<const float> weights,
                                       absl::Span<const Vec3f> normals) {
  NM_RETURN_IF_ERROR(ValidateBatch(positions, weights, normals));
  const size_t n = positions.size();
  BoundingBox batch_bounds;
  for (const Vec3f& p : positions) batch_bounds.Extend(Vec3(p));
  float batch_max_weight = 0.0f;
  for (const float w : weights) batch_max_weight = std::max(batch_max_weight, w);
  if (n == 0) return absl::OkStatus();

  std::lock_guard<std::mutex> lock(append_mu_);
  // Only this thread changes size_, so a relaxed load sees the latest value.
  const size_t old_size = size_.load(std::memory_order_relaxed);
  NM_RETURN_IF_ERROR(CheckRoom(n, old_size, !weights.empty() && batch_max_weight == 0.0f));

  // Earlier points weigh 1 and have a zero normal; they get them, and the weight-1 class, before
  // the flag that lets readers look for them.
  if (!weights.empty() && !has_weights_.load(std::memory_order_relaxed)) {
    Fill(weight_chunks_, 0, old_size, 1.0f);
    Classify(0, old_size, {});
    PublishClasses();
    has_weights_.store(true, std::memory_order_release);
  }
  if (!normals.empty() && !has_normals_.load(std::memory_order_relaxed)) {
    Fill(normal_chunks_, 0, old_size, Vec3f(0.0f, 0.0f, 0.0f));
    has_normals_.store(true, std::memory_order_release);
  }

  Store(position_chunks_, old_size, positions);
  const bool weighted = has_weights_.load(std::memory_order_relaxed);
  if (weighted) {
    if (weights.empty()) {
      Fill(weight_chunks_, old_size, old_size + n, 1.0f);
    } else {
      Store(weight_chunks_, old_size, weights);
    }
  }
  if (has_normals_.load(std::memory_order_relaxed)) {
    if (normals.empty()) {
      Fill(normal_chunks_, old_size, old_size + n, Vec3f(0.0f, 0.0f, 0.0f));
    } else {
      Store(normal_chunks_, old_size, normals);
    }
  }
  {
    std::lock_guard<std::mutex> bounds_lock(bounds_mu_);
    bounds_.Extend(batch_bounds);
  }
  // The batch's points join their classes after size_ counts them, so that a sample is always
  // below size(); those of a first batch before, as a reader samples as soon as size_ is not 0
  // and must find a class with members then.
  if (weighted) Classify(old_size, old_size + n, weights);
  if (weighted && old_size == 0) PublishClasses();
  size_.store(old_size + n, std::memory_order_release);
  if (weighted && old_size != 0) PublishClasses();
  return absl::OkStatus();
}

absl::Status GrowingPointCloud::CheckRoom(size_t n, size_t old_size,
                                          bool weights_all_zero) const {
  if (n > max_points_ - old_size) {
    return absl::ResourceExhaustedError(absl::StrCat("appending ", n, " points to ", old_size,
                                                     " would exceed the capacity of ", max_points_,
                                                     " points"));
  }
  if (old_size == 0 && weights_all_zero) {
    return absl::InvalidArgumentError(
        "every weight of the first batch is zero: there would be nothing to sample");
  }
  return absl::OkStatus();
}

absl::Status GrowingPointCloud::CheckRoomFor(const PointCloud& batch) const {
  if (batch.positions.empty()) return absl::OkStatus();
  const size_t old_size = size();
  // Only the first batch's weights matter (CheckRoom).
  const bool weights_all_zero =
      old_size == 0 && !batch.weights.empty() &&
      std::all_of(batch.weights.begin(), batch.weights.end(), [](float w) { return w == 0.0f; });
  return CheckRoom(batch.positions.size(), old_size, weights_all_zero);
}

absl::Status GrowingPointCloud::Append(const PointCloud& batch) {
  return Append(batch.positions, batch.weights, batch.normals);
}

void GrowingPointCloud::LoadClasses(ClassSnapshot* snapshot) const {
  snapshot->classes = class_list_size_.load(std::memory_order_acquire);
  double sum = 0;
  for (size_t p = 0; p < snapshot->classes; ++p) {
    snapshot->counts[p] = class_counts_[p].load(std::memory_order_acquire);
    sum += static_cast<double>(snapshot->counts[p]) * class_bounds_[p];
    snapshot->cumulative[p] = sum;
  }
}

size_t GrowingPointCloud::PickClass(Random& rng, const ClassSnapshot& snapshot) {
  if (snapshot.classes == 1) return 0;
  // The last class takes what rounding leaves over.
  const double r = rng.NextDouble() * snapshot.total();
  size_t p = 0;
  while (p + 1 < snapshot.classes && !(r < snapshot.cumulative[p])) ++p;
  return p;
}

const GrowingPointCloud::Member& GrowingPointCloud::PickMember(Random& tries,
                                                               const ClassSnapshot& snapshot,
                                                               double* bound) const {
  const size_t p = PickClass(tries, snapshot);
  *bound = class_bounds_[p];
  return class_list_[p]->MemberRef(tries.NextIndex(snapshot.counts[p]));
}

bool GrowingPointCloud::Keep(Random& tries, const Member& member, double bound) {
  return member.weight == bound || tries.NextDouble() * bound < member.weight;
}

Vec3 GrowingPointCloud::Sample(Random& rng, int* tries_taken) const {
  if (tries_taken != nullptr) *tries_taken = 1;
  const size_t n = size_.load(std::memory_order_acquire);
  if (n == 0) return Vec3(0.0, 0.0, 0.0);
  if (!has_weights_.load(std::memory_order_acquire)) return Vec3(PositionAt(rng.NextIndex(n)));
  // One snapshot of the classes for the whole draw, so that every try picks from the same
  // distribution; members published meanwhile wait for the next sample. Every listed class has
  // members, and one at least is listed once has_weights_ is set.
  ClassSnapshot snapshot;
  LoadClasses(&snapshot);
  Random tries(rng.NextU64());  // One draw of `rng` per sample, however many tries it takes.
  if (!(snapshot.total() > 0)) return Vec3(0.0, 0.0, 0.0);  // Unreachable; never loop on nothing.
  for (int try_count = 1;; ++try_count) {
    // The class at list position p with probability counts[p] * U_p / total, then a uniform
    // member, kept with probability w / U in (1/2, 1] (exact: U is a power of two).
    double bound;
    const Member& member = PickMember(tries, snapshot, &bound);
    if (Keep(tries, member, bound)) {
      if (tries_taken != nullptr) *tries_taken = try_count;
      return Vec3(PositionAt(member.point));
    }
  }
}

void GrowingPointCloud::PrefetchSample(const Random& rng) const {
  const size_t n = size_.load(std::memory_order_acquire);
  if (n == 0) return;
  Random peek = rng;
  if (!has_weights_.load(std::memory_order_acquire)) {
    __builtin_prefetch(&PositionAt(peek.NextIndex(n)));
    return;
  }
  // A weighted sample reads a member, then its point, one cache miss after the other: loaded
  // over two calls, one Basic Step apart. Each sample takes one draw of `rng`, so the sample
  // after the next one is known too.
  ClassSnapshot snapshot;
  LoadClasses(&snapshot);
  if (!(snapshot.total() > 0)) return;
  Random next_tries(peek.NextU64());
  Random later_tries(peek.NextU64());
  double bound;
  // The sample after the next one: its first try's member starts loading.
  __builtin_prefetch(&PickMember(later_tries, snapshot, &bound));
  // The next sample: its first try's member, loaded by the last call, is read; its point starts
  // loading, or when the try fails, the next try's member.
  const Member& member = PickMember(next_tries, snapshot, &bound);
  if (Keep(next_tries, member, bound)) {
    __builtin_prefetch(&PositionAt(member.point));
  } else {
    __builtin_prefetch(&PickMember(next_tries, snapshot, &bound));
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
