// Regenerates the close-range golden set (golden_io.h) into DIR:
//   devel/lib/ardsim_pose/pose_close_range_make_golden [--estimates-only]
//   src/ardsim_pose/test/close_range/golden
// --estimates-only: the expected estimates of the frames already there (after a change to the methods: the
// frames rendered again now are other noise draws than the committed ones, a median 10 mm a pixel apart).
// Frames: the ISS docking adapter rendered with noise on (seed 7) along golden::goldenRanges(); expected
// estimates of the ring and pyramid methods, each frame predicted from its truth disturbed
// (golden::goldenPrediction).
#include <cstdio>
#include <fstream>
#include <string>

#include "ardsim_pose/close_range/pyramid.h"
#include "ardsim_pose/close_range/ring_detector.h"
#include "golden_io.h"
#include "rendering.h"

using namespace ardsim_pose::close_range;

// The frames rendered and written into dir with truth.csv, as read back.
bool renderFrames(const std::string& dir, std::vector<ardsim_pose::OrganizedCloud>* frames,
                  std::vector<Eigen::Isometry3d>* truths) {
  testing::TargetRenderer renderer(true, 7);
  std::ofstream truth(dir + "/truth.csv");
  truth.precision(12);
  truth << "# frame x y z qx qy qz qw: T_lidar_target, m (noise on, seed 7)\n";
  const std::vector<double> ranges = golden::goldenRanges();
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    testing::ApproachState s;
    s.port_range_m = ranges[k];
    s.tilt_y_deg = 3.0 - 0.5 * k;
    s.tilt_z_deg = -2.0 + 0.3 * k;
    s.lateral_y_m = 0.06 - 0.01 * k;
    s.lateral_z_m = -0.04 + 0.006 * k;
    s.roll_deg = 12.0 - 2.0 * k;
    const Eigen::Isometry3d T = testing::T_lidar_target(s);
    truths->push_back(T);
    frames->push_back(renderer.render(T, k));
    // Stored as read back (millimetre ranges), so the expected estimates are those of the stored frames.
    golden::writeFrame(dir, static_cast<int>(k), frames->back());
    if (!golden::readFrame(dir, static_cast<int>(k), &frames->back())) return false;
    golden::writeRow(truth, {static_cast<int>(k), T, 0, 0}, false);
  }
  return true;
}

int main(int argc, char** argv) {
  const bool estimates_only = argc == 3 && std::string(argv[1]) == "--estimates-only";
  if (argc != 2 && !estimates_only) {
    std::fprintf(stderr, "usage: %s [--estimates-only] OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[argc - 1];
  std::vector<ardsim_pose::OrganizedCloud> frames;
  std::vector<Eigen::Isometry3d> truths;
  if (estimates_only) {
    for (const golden::Row& row : golden::readRows(dir + "/truth.csv", false)) {
      truths.push_back(row.T);
      frames.emplace_back();
      if (!golden::readFrame(dir, row.index, &frames.back())) {
        std::fprintf(stderr, "cannot read frame %d in %s\n", row.index, dir.c_str());
        return 2;
      }
    }
  } else if (!renderFrames(dir, &frames, &truths)) {
    std::fprintf(stderr, "cannot write frames into %s\n", dir.c_str());
    return 2;
  }
  RingMethod ring;
  PyramidMethod pyramid;
  for (auto [name, method] :
       {std::pair<const char*, ardsim_pose::PoseMethod*>{"ring", &ring}, {"pyramid", &pyramid}}) {
    std::ofstream out(dir + "/expected_" + name + ".csv");
    out.precision(12);
    out << "# frame x y z qx qy qz qw status observed: estimated T_lidar_target (status 0 tracking, 1 "
           "degraded, 2 "
           "lost)\n";
    for (const golden::Row& row : golden::estimateAll(*method, frames, truths))
      golden::writeRow(out, row, true);
  }
  std::printf("wrote %s%zu frames' expected estimates to %s\n", estimates_only ? "" : "the frames and ",
              frames.size(), dir.c_str());
  return 0;
}
