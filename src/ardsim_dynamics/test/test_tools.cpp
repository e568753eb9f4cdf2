// The command-line tools as a user runs them: output, and one-line errors with exit status 2.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ardsim_dynamics/gravity_field.h"

namespace {

struct ToolRun {
  int status = -1;
  std::string output;  // stdout and stderr
};

ToolRun run(const std::string& command) {
  ToolRun result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  std::array<char, 4096> buffer{};
  while (pipe && fgets(buffer.data(), buffer.size(), pipe)) result.output += buffer.data();
  const int raw = pipe ? pclose(pipe) : -1;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return result;
}

}  // namespace

TEST(GravityEval, PrintsTheLibrarysAccelerationAtFullPrecision) {
  const ToolRun r = run(std::string(GRAVITY_EVAL) + " --degree 13 1200000 -5100000 4300000");
  ASSERT_EQ(r.status, 0) << r.output;
  std::istringstream in(r.output);
  double ax, ay, az;
  ASSERT_TRUE(in >> ax >> ay >> az) << r.output;
  const Eigen::Vector3d a =
      ardsim_dynamics::GravityField::egm96().acceleration(Eigen::Vector3d(1.2e6, -5.1e6, 4.3e6), 13);
  EXPECT_EQ(ax, a.x());
  EXPECT_EQ(ay, a.y());
  EXPECT_EQ(az, a.z());
}

TEST(GravityEval, ReadsAModelFileAndRejectsDegreesAboveIt) {
  const std::string path = ::testing::TempDir() + "/j2.txt";
  {
    std::ofstream out(path);
    out << "# J2 only\n# GM = 3.986004415e14\n# R = 6378136.3\n 2 0 -4.84165371736e-04 0\n";
  }
  const ToolRun ok = run(std::string(GRAVITY_EVAL) + " --model " + path + " --degree 2 7000000 0 0");
  EXPECT_EQ(ok.status, 0) << ok.output;
  const ToolRun too_high = run(std::string(GRAVITY_EVAL) + " --model " + path + " --degree 5 7000000 0 0");
  EXPECT_EQ(too_high.status, 2);
  EXPECT_NE(too_high.output.find("degree 5 is above the model's maximum degree 2"), std::string::npos)
      << too_high.output;
  EXPECT_EQ(std::count(too_high.output.begin(), too_high.output.end(), '\n'), 1) << too_high.output;
}

TEST(GravityEval, UnreadableFileAndBadArgumentsExitWith2) {
  const ToolRun missing = run(std::string(GRAVITY_EVAL) + " --model /nonexistent.txt --degree 2 7000000 0 0");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("/nonexistent.txt"), std::string::npos) << missing.output;
  EXPECT_EQ(run(std::string(GRAVITY_EVAL) + " --degree 2 7000000 0").status, 2);
  EXPECT_EQ(run(std::string(GRAVITY_EVAL) + " 7000000 0 0").status, 2);
  EXPECT_EQ(run(std::string(GRAVITY_EVAL) + " --degree two 7000000 0 0").status, 2);
}

TEST(Propagate, WritesOneRowPerSampleWithTheInitialRelativeState) {
  const std::string out = ::testing::TempDir() + "/drift.csv";
  const ToolRun r = run(std::string(PROPAGATE) + " " + SCENARIO_DIR +
                        "/free_drift.yaml --duration 60 --every 10 --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(out);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("t_s,target_x_m", 0), 0u) << header;
  int rows = 0;
  std::string first;
  while (std::getline(in, line)) {
    if (rows == 0) first = line;
    ++rows;
  }
  EXPECT_EQ(rows, 7);  // t = 0, 10, ..., 60
  // The LVLH columns of the first row are the scenario's initial relative state.
  std::istringstream cells(first);
  std::vector<double> values;
  for (std::string cell; std::getline(cells, cell, ',');) values.push_back(std::stod(cell));
  ASSERT_EQ(values.size(), 1u + 26u + 9u);
  EXPECT_NEAR(values[27], -100.0, 1e-6);
  EXPECT_NEAR(values[29], 20.0, 1e-6);
  EXPECT_EQ(run(std::string(PROPAGATE) + " /nonexistent.yaml").status, 2);
  EXPECT_EQ(run(std::string(PROPAGATE) + " " + SCENARIO_DIR + "/free_drift.yaml --every -1").status, 2);
}
