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
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
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

constexpr uint64_t kTurnSteps = 20000;

struct Weighting {
  std::string name;
  // Draws the weight of one point; empty for a cloud without weights.
  std::function<float(Random&)> weight;
};

struct Contender {
  std::string target_space;
  std::string weights;
  std::unique_ptr<Sampler> sampler;
  std::unique_ptr<Learner> learner;
  double seconds = 0;
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

// Adds a learner with the paper's parameters on `sampler`; false (with a message) when the
// sampler could not be made.
bool AddContender(std::string target_space, std::string weights,
                  absl::StatusOr<std::unique_ptr<Sampler>> sampler, uint64_t seed,
                  std::vector<Contender>& contenders) {
  if (!sampler.ok()) {
    std::fprintf(stderr, "weighted-sampling-bench: %s\n",
                 std::string(sampler.status().message()).c_str());
    return false;
  }
  Contender c;
  c.target_space = std::move(target_space);
  c.weights = std::move(weights);
  c.sampler = *std::move(sampler);
  LearnerOptions options;
  options.seed = seed;
  c.learner = Learner::Create(options, c.sampler.get()).value();
  contenders.push_back(std::move(c));
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
                        MakeSampler(growing, points, std::move(weights)), seed, contenders)) {
        return 1;
      }
    }
  }
  if (!AddContender("MeshSampler", "triangle area",
                    MeshSampler::Create(std::make_shared<const TriangleMesh>(TorusMesh(n))), seed,
                    contenders)) {
    return 1;
  }

  for (bool all_done = false; !all_done;) {
    all_done = true;
    for (Contender& c : contenders) {
      if (c.learner->num_vertices() >= vertices) continue;
      all_done = false;
      StopCriteria turn;
      turn.max_basic_steps = kTurnSteps;
      turn.target_vertices = vertices;
      const auto start = std::chrono::steady_clock::now();
      if (absl::StatusOr<StopReason> stop = c.learner->Run(turn); !stop.ok()) {
        std::fprintf(stderr, "weighted-sampling-bench: %s, %s: %s\n", c.target_space.c_str(),
                     c.weights.c_str(),
                     std::string(stop.status().message()).c_str());
        return 1;
      }
      c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  }

  std::printf("%llu torus points to %llu vertices, paper parameters, one thread, turns of %llu "
              "Basic Steps\n\n",
              static_cast<unsigned long long>(n), static_cast<unsigned long long>(vertices),
              static_cast<unsigned long long>(kTurnSteps));
  std::printf("%-18s %-27s %8s %12s %8s %14s\n", "target space", "weights", "seconds",
              "Basic Steps", "us/step", "vs no weights");
  auto us_per_step = [](const Contender& c) {
    return 1e6 * c.seconds / static_cast<double>(c.learner->progress().basic_steps);
  };
  double base_us = 0;
  for (const Contender& c : contenders) {
    const uint64_t steps = c.learner->progress().basic_steps;
    const double us = us_per_step(c);
    if (c.weights == weightings[0].name) base_us = us;
    // The mesh against the points of the loaded file without weights, the first row.
    if (c.target_space == "MeshSampler") base_us = us_per_step(contenders[0]);
    std::printf("%-18s %-27s %8.2f %12llu %8.3f %14.2f\n", c.target_space.c_str(),
                c.weights.c_str(), c.seconds, static_cast<unsigned long long>(steps), us,
                us / base_us);
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
