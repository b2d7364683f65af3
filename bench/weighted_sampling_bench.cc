// Weighted sampling benchmark: the learner on N points of a torus (R = 1, r = 0.35) without
// weights and with three weightings (Section 4.1's per-point confidence), each to V vertices
// with the paper's parameters on one thread, for both target spaces that hold point clouds: a
// loaded file's (PointCloudSampler: an alias table) and the server's (GrowingPointCloud: weight
// classes); and on a torus mesh of N triangles sampled by area (MeshSampler, Section 4.1's
// uniform remeshing). The nine learners take turns of 20,000 Basic Steps, so that the
// machine's drift meets them alike. Prints each one's time per Basic Step and its ratio to the
// same target space's without weights (the mesh: to the point cloud's); it is not a test.
//
//   build/bin/weighted-sampling-bench [--points=1000000] [--vertices=20000] [--seed=1]
//
// A weighted draw reads a table cell or a class member (a cache miss on a large cloud) and then
// the point it names (another); a mesh's draw reads a cell, a face, then its corners. Each
// sampler's PrefetchSample loads them over as many Basic Steps.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "bench/band_timer.h"
#include "bench/bench_flags.h"
#include "core/learning/learner.h"
#include "core/random.h"
#include "core/sampling/growing_point_cloud.h"
#include "core/sampling/implicit_surfaces.h"
#include "core/sampling/mesh_sampler.h"
#include "core/sampling/point_cloud_sampler.h"
#include "core/sampling/sample_points.h"
#include "core/triangle_mesh.h"

ABSL_FLAG(uint64_t, points, 1000000,
          "Points of the torus in each cloud, and about as many triangles in the mesh.");
ABSL_FLAG(uint64_t, vertices, 20000, "Vertex count each learner learns to.");
ABSL_FLAG(uint64_t, seed, 1, "Seed of the points, the weights and the learners.");

namespace neuralmesh {
namespace {

struct Weighting {
  std::string name;
  // Draws the weight of one point; empty for a cloud without weights.
  std::function<float(Random&)> weight;
};

// One learner's target space, by name, and the sampler its learner draws from.
struct Contender {
  std::string target_space;
  std::string weights;
  std::unique_ptr<Sampler> sampler;
};

// The torus as a mesh of about `faces` triangles: a grid over its two angles, twice as many
// steps around the main circle as around the tube.
TriangleMesh TorusMesh(uint64_t faces) {
  const uint32_t around_tube =
      std::max<uint32_t>(3, static_cast<uint32_t>(std::sqrt(static_cast<double>(faces) / 4)));
  const uint32_t around_axis = 2 * around_tube;
  TriangleMesh mesh;
  for (uint32_t i = 0; i < around_axis; ++i) {
    const double u = 2 * M_PI * i / around_axis;
    for (uint32_t j = 0; j < around_tube; ++j) {
      const double v = 2 * M_PI * j / around_tube;
      const double rho = 1.0 + 0.35 * std::cos(v);
      mesh.positions.emplace_back(static_cast<float>(rho * std::cos(u)),
                                  static_cast<float>(rho * std::sin(u)),
                                  static_cast<float>(0.35 * std::sin(v)));
    }
  }
  auto index = [&](uint32_t i, uint32_t j) {
    return (i % around_axis) * around_tube + j % around_tube;
  };
  for (uint32_t i = 0; i < around_axis; ++i) {
    for (uint32_t j = 0; j < around_tube; ++j) {
      mesh.faces.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      mesh.faces.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  return mesh;
}

// The two target spaces for the same points and weights.
absl::StatusOr<std::unique_ptr<Sampler>> MakeSampler(bool growing, const PointCloud& points,
                                                     std::vector<float> weights) {
  if (growing) {
    auto cloud = std::make_unique<GrowingPointCloud>();
    if (absl::Status status = cloud->Append(points.positions, weights); !status.ok()) {
      return status;
    }
    return std::unique_ptr<Sampler>(std::move(cloud));
  }
  auto cloud = std::make_shared<PointCloud>();
  cloud->positions = points.positions;
  cloud->weights = std::move(weights);
  return MakePointCloudSampler(std::move(cloud));
}

// Adds a contender on `sampler`; false (with a message) when the sampler could not be made.
bool AddContender(std::string target_space, std::string weights,
                  absl::StatusOr<std::unique_ptr<Sampler>> sampler,
                  std::vector<Contender>& contenders) {
  if (!sampler.ok()) {
    std::fprintf(stderr, "weighted-sampling-bench: %s\n",
                 std::string(sampler.status().message()).c_str());
    return false;
  }
  contenders.push_back({std::move(target_space), std::move(weights), *std::move(sampler)});
  return true;
}

int Run() {
  const uint64_t n = absl::GetFlag(FLAGS_points);
  const uint64_t vertices = absl::GetFlag(FLAGS_vertices);
  const uint64_t seed = absl::GetFlag(FLAGS_seed);
  if (n < 4 || vertices < 4 || vertices > n / 2) {
    std::fprintf(stderr,
                 "weighted-sampling-bench: need --points >= 4 and 4 <= --vertices <= points / 2 "
                 "(got %llu and %llu)\n",
                 static_cast<unsigned long long>(n), static_cast<unsigned long long>(vertices));
    return 2;
  }
  const std::vector<Weighting> weightings = {
      {"no weights", nullptr},
      {"every weight 1", [](Random&) { return 1.0f; }},
      {"uniform in (0, 1]",
       [](Random& rng) { return static_cast<float>(1.0 - rng.NextDouble()); }},
      {"log-uniform over 3 decades",
       [](Random& rng) { return static_cast<float>(std::pow(10.0, -3.0 * rng.NextDouble())); }},
  };

  auto torus = MakeTorus(Vec3(0, 0, 0), 1.0, 0.35).value();
  const PointCloud points = SamplePoints(*torus, n, seed);
  std::vector<Contender> contenders;
  for (bool growing : {false, true}) {
    Random weight_rng(seed);
    for (const Weighting& weighting : weightings) {
      std::vector<float> weights;
      if (weighting.weight) {
        weights.reserve(n);
        for (uint64_t i = 0; i < n; ++i) weights.push_back(weighting.weight(weight_rng));
      }
      if (!AddContender(growing ? "GrowingPointCloud" : "PointCloudSampler", weighting.name,
                        MakeSampler(growing, points, std::move(weights)), contenders)) {
        return 1;
      }
    }
  }
  if (!AddContender("MeshSampler", "triangle area",
                    MeshSampler::Create(std::make_shared<const TriangleMesh>(TorusMesh(n))),
                    contenders)) {
    return 1;
  }

  std::vector<std::unique_ptr<Learner>> learners;
  std::vector<BandTimer> timers;
  for (const Contender& c : contenders) {
    LearnerOptions options;
    options.seed = seed;
    learners.push_back(Learner::Create(options, c.sampler.get()).value());
    timers.emplace_back(std::vector<size_t>{vertices});
  }
  if (absl::Status status = TakeTurns(learners, timers); !status.ok()) {
    std::fprintf(stderr, "weighted-sampling-bench: %s\n", std::string(status.message()).c_str());
    return 1;
  }

  std::printf(
      "%llu torus points to %llu vertices, paper parameters, one thread, turns of %llu "
      "Basic Steps\n\n",
      static_cast<unsigned long long>(n), static_cast<unsigned long long>(vertices),
      static_cast<unsigned long long>(BandTimer::kTurnSteps));
  std::printf("%-18s %-27s %8s %12s %8s %14s\n", "target space", "weights", "seconds",
              "Basic Steps", "us/step", "vs no weights");
  auto us_per_step = [&](size_t i) {
    return 1e6 * timers[i].total_seconds() / static_cast<double>(timers[i].total_steps());
  };
  double base_us = 0;
  for (size_t i = 0; i < contenders.size(); ++i) {
    const Contender& c = contenders[i];
    const double us = us_per_step(i);
    if (c.weights == weightings[0].name) base_us = us;
    // The mesh against the points of the loaded file without weights, the first row.
    if (c.target_space == "MeshSampler") base_us = us_per_step(0);
    std::printf("%-18s %-27s %8.2f %12llu %8.3f %14.2f\n", c.target_space.c_str(),
                c.weights.c_str(), timers[i].total_seconds(),
                static_cast<unsigned long long>(timers[i].total_steps()), us, us / base_us);
  }
  return 0;
}

}  // namespace
}  // namespace neuralmesh

int main(int argc, char** argv) {
  neuralmesh::ParseBenchFlags(
      argc, argv,
      "Times the learner on point clouds without and with weights and on a mesh sampled by "
      "area; see bench/weighted_sampling_bench.cc");
  return neuralmesh::Run();
}
