// The pipelined sequence (datasets, benchmarks) must give exactly the frames of one-at-a-time simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <vector>

#include "ardsim_description/models.h"
#include "ardsim_lidar/docking_views.h"
#include "ardsim_lidar/lidar_simulator.h"

namespace ardsim_lidar {
namespace {

// Bitwise: NaN (no return) where the other has NaN, the same floats elsewhere.
bool identical(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

std::vector<Eigen::Isometry3d> approach(std::size_t count) {
  std::vector<Eigen::Isometry3d> poses;
  for (std::size_t k = 0; k < count; ++k)
    poses.push_back(lidarOnDockingAxis(ardsim_description::TargetKind::kIss, 60.0 - 7.0 * k));
  return poses;
}

TEST(Sequence, RenderedFramesEqualSingleRendersInOrder) {
  EglRenderer renderer{SensorOptions{}};
  renderer.setMesh(ardsim_description::buildIss());
  // Fewer frames than the renderer keeps in flight, and more; and none.
  for (const std::size_t count : {std::size_t{0}, std::size_t{2}, std::size_t{8}}) {
    const std::vector<Eigen::Isometry3d> poses = approach(count);
    std::vector<std::size_t> order;
    std::vector<RenderedFrame> frames;
    renderer.renderSequence(poses, [&](std::size_t k, TriangleIdFrame& ids) {
      order.push_back(k);
      frames.emplace_back();
      renderer.resolve(ids, poses[k], &frames.back());
    });
    ASSERT_EQ(order.size(), count);
    for (std::size_t k = 0; k < count; ++k) {
      EXPECT_EQ(order[k], k);
      RenderedFrame single;
      renderer.render(poses[k], &single);
      ASSERT_EQ(single.pixels.size(), frames[k].pixels.size());
      EXPECT_EQ(std::memcmp(single.pixels.data(), frames[k].pixels.data(),
                            single.pixels.size() * sizeof(SurfaceSample)),
                0)
          << "frame " << k << " of " << count;
    }
  }
}

TEST(Sequence, NoisyFramesEqualSimulateWithTheSameFrameIndex) {
  LidarSimulator simulator(SensorOptions{}, NoiseOptions{}, 5);
  simulator.setTarget(ardsim_description::buildIss());
  const std::vector<Eigen::Isometry3d> poses = approach(9);
  const std::uint64_t first_index = 100;
  std::vector<LidarFrame> frames(poses.size());
  std::vector<int> calls(poses.size(), 0);
  std::mutex mutex;
  simulator.simulateSequence(poses, first_index, [&](std::size_t k, const LidarFrame& frame) {
    std::lock_guard<std::mutex> lock(mutex);
    frames[k] = frame;
    ++calls[k];
  });
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_EQ(calls[k], 1) << "frame " << k;
    LidarFrame single;
    simulator.simulate(poses[k], first_index + k, &single);
    EXPECT_GT(single.returnCount(), 1000u) << "frame " << k;
    EXPECT_TRUE(identical(single.range_m, frames[k].range_m)) << "frame " << k;
    EXPECT_TRUE(identical(single.intensity, frames[k].intensity)) << "frame " << k;
  }
}

TEST(Sequence, AnErrorInTheConsumerReachesTheCaller) {
  LidarSimulator simulator(SensorOptions{}, NoiseOptions{}, 5);
  simulator.setTarget(ardsim_description::buildIss());
  EXPECT_THROW(simulator.simulateSequence(approach(6), 0,
                                          [](std::size_t k, const LidarFrame&) {
                                            if (k == 3) throw std::runtime_error("disk full");
                                          }),
               std::runtime_error);
  // The renderer is still usable.
  LidarFrame frame;
  simulator.simulate(approach(1)[0], 0, &frame);
  EXPECT_GT(frame.returnCount(), 1000u);
}

}  // namespace
}  // namespace ardsim_lidar
