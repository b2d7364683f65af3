// Colours from coloured points, a fixed set (MakePointColorSource) or a growing one
// (GrowingPointColors): the k nearest, weighted by inverse distance.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/analysis/color_source.h"

namespace neuralmesh {
namespace {

constexpr int kMaxNeighbours = 64;

// A point this close counts as the vertex's own: its weight 1 / distance outweighs the rest.
constexpr double kMinDistance = 1e-12;

// The inverse-distance weighted mean of the colours of the points in `heap`, which it empties;
// at least one.
Rgb BlendNearest(NeighbourHeap& heap, absl::Span<const Rgb> colors) {
  double sum[3] = {0, 0, 0};
  double total = 0;
  for (; !heap.empty(); heap.pop()) {
    const auto [squared_distance, index] = heap.top();
    const double weight = 1.0 / std::max(std::sqrt(double{squared_distance}), kMinDistance);
    for (int c = 0; c < 3; ++c) sum[c] += weight * colors[index][c];
    total += weight;
  }
  Rgb color;
  for (int c = 0; c < 3; ++c) color[c] = ChannelFromLevel(sum[c] / total, 255.0);
  return color;
}

class PointColorSource final : public ColorSource {
 public:
  PointColorSource(const PointCloud& cloud, size_t neighbours)
      : colors_(cloud.colors),
        neighbours_(neighbours),
        tree_(cloud.positions, 0, static_cast<uint32_t>(cloud.positions.size())) {}

  Rgb ColorAt(const Vec3f& position) const override {
    NeighbourHeap heap;
    tree_.Search(position, UINT32_MAX, neighbours_, &heap);
    return BlendNearest(heap, colors_);
  }

 private:
  std::vector<Rgb> colors_;
  size_t neighbours_;
  PointKdTree tree_;  // Holds the points.
};

}  // namespace

void ColorSource::Paint(TriangleMesh* mesh) const {
  mesh->colors.resize(mesh->positions.size());
  for (size_t v = 0; v < mesh->positions.size(); ++v) mesh->colors[v] = ColorAt(mesh->positions[v]);
}

absl::Status PointColorOptions::Validate() const {
  if (neighbours < 1 || neighbours > kMaxNeighbours) {
    return absl::InvalidArgumentError(absl::StrCat("colour neighbours = ", neighbours,
                                                   " is out of range; it must be in [1, ",
                                                   kMaxNeighbours, "]"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<ColorSource>> MakePointColorSource(
    const PointCloud& cloud, const PointColorOptions& options) {
  if (absl::Status valid = options.Validate(); !valid.ok()) return valid;
  if (cloud.empty()) return absl::InvalidArgumentError("there are no points to take colours from");
  if (cloud.colors.size() != cloud.size()) {
    return absl::InvalidArgumentError(absl::StrCat("the points carry ", cloud.colors.size(),
                                                   " colours for ", cloud.size(), " points"));
  }
  return std::make_unique<PointColorSource>(cloud, static_cast<size_t>(options.neighbours));
}

GrowingPointColors::GrowingPointColors(const PointColorOptions& options)
    : neighbours_(static_cast<size_t>(options.neighbours)) {}

void GrowingPointColors::Append(absl::Span<const Vec3f> positions, absl::Span<const Rgb> colors) {
  const size_t n = std::min(positions.size(), colors.size());
  std::lock_guard<std::mutex> lock(queue_mu_);
  queued_positions_.insert(queued_positions_.end(), positions.begin(), positions.begin() + n);
  queued_colors_.insert(queued_colors_.end(), colors.begin(), colors.begin() + n);
}

size_t GrowingPointColors::size() const {
  std::lock_guard<std::mutex> lock(queue_mu_);
  return taken_ + queued_positions_.size();
}

void GrowingPointColors::Paint(TriangleMesh* mesh) {
  std::lock_guard<std::mutex> lock(paint_mu_);
  std::vector<Vec3f> arrived;
  {
    std::lock_guard<std::mutex> queue(queue_mu_);
    arrived.swap(queued_positions_);
    colors_.insert(colors_.end(), queued_colors_.begin(), queued_colors_.end());
    taken_ += arrived.size();
    queued_colors_.clear();
  }
  const auto n = static_cast<uint32_t>(colors_.size());
  if (n == 0) return;
  if (!arrived.empty()) {
    // The trees hold the points: the tree rebuilt takes those of the trees it replaces.
    const uint32_t head_end = head_.has_value() ? head_->end() : 0;
    const bool whole = n - head_end > head_end / 4;
    std::vector<PointKdTree> replaced;
    for (std::optional<PointKdTree>* tree : {&head_, &tail_}) {
      if (!tree->has_value() || (tree == &head_ && !whole)) continue;
      replaced.push_back(*std::move(*tree));
      tree->reset();
    }
    (whole ? head_ : tail_)
        .emplace(PointKdTree::Merged(std::move(replaced), n - static_cast<uint32_t>(arrived.size()),
                                     arrived));
  }
  mesh->colors.resize(mesh->positions.size());
  NeighbourHeap heap;
  for (size_t v = 0; v < mesh->positions.size(); ++v) {
    head_->Search(mesh->positions[v], UINT32_MAX, neighbours_, &heap);
    if (tail_.has_value()) {
      tail_->Search(mesh->positions[v], UINT32_MAX, neighbours_, &heap);
    }
    mesh->colors[v] = BlendNearest(heap, colors_);
  }
}

}  // namespace neuralmesh
