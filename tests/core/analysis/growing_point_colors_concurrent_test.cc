// GrowingPointColors appended to on one thread while another paints (run under
// ThreadSanitizer by scripts/test.sh).
#include <atomic>
#include <thread>

#include "core/analysis/color_source.h"
#include "gtest/gtest.h"
#include "tests/testing/shapes.h"

namespace neuralmesh {
namespace {

TEST(GrowingPointColorsConcurrentTest, PaintsWhilePointsArrive) {
  const PointCloud cloud = testing::ColoredUnitSpherePoints(20000, 5);
  GrowingPointColors growing;
  std::atomic<bool> done{false};
  std::thread appender([&] {
    for (size_t begin = 0; begin < cloud.size(); begin += 500) {
      growing.Append(absl::MakeConstSpan(cloud.positions).subspan(begin, 500),
                     absl::MakeConstSpan(cloud.colors).subspan(begin, 500));
    }
    done = true;
  });
  TriangleMesh mesh = testing::Icosphere(2);
  int paints = 0;
  while (!done || paints == 0) {
    growing.Paint(&mesh);
    ++paints;
  }
  appender.join();
  growing.Paint(&mesh);
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    EXPECT_LE(testing::ColorError(mesh.colors[v], mesh.positions[v]), 4) << "vertex " << v;
  }
  EXPECT_EQ(growing.size(), cloud.size());
}

}  // namespace
}  // namespace neuralmesh
