#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "ardsim_dynamics/orbit.h"
#include "ardsim_guidance/relative_navigator.h"

using namespace ardsim_guidance;

namespace {

const double kN = 1.12762e-3;

// RMS velocity error of a navigator fed with the same noisy positions of a CW trajectory with a constant
// commanded deceleration (known to both), after a settling time.
double velocityNoise(VelocitySource source, double sigma, int seed) {
  NavigatorOptions o;
  o.velocity_source = source;
  o.measurement_sigma_m = sigma;
  RelativeNavigator nav(o);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Vector6d truth;
  truth << 60.0, 1.0, -0.5, -0.2, 0.0, 0.0;
  const Eigen::Vector3d accel(1e-4, 0.0, 0.0), offset(0.0, 0.0, 0.0);
  const double dt = 0.1;
  double sum_sq = 0.0;
  int count = 0;
  for (int k = 0; k < 3000; ++k) {
    if (k > 0) {
      nav.predict(dt, kN, offset, accel);
      const Vector6d free = ardsim_dynamics::cwTransition(kN, dt) * truth;
      truth = free;
      truth.head<3>() += 0.5 * dt * dt * accel;
      truth.tail<3>() += dt * accel;
    }
    Eigen::Vector3d measured = truth.head<3>();
    for (int i = 0; i < 3; ++i) measured[i] += noise(rng);
    nav.update(measured);
    if (k >= 600) {
      sum_sq += (nav.velocity() - truth.tail<3>()).squaredNorm();
      ++count;
    }
  }
  return std::sqrt(sum_sq / count);
}

}  // namespace

TEST(Navigator, BothSourcesFollowANoiseFreeTrajectory) {
  for (VelocitySource source : {VelocitySource::kKalman, VelocitySource::kDifferencing}) {
    EXPECT_LT(velocityNoise(source, 1e-9, 1), 2e-3);
  }
}

TEST(Navigator, KalmanVelocityIsQuieterThanDifferencing) {
  // 5 cm per axis, the default measurement sigma. Measured (seed 7): differencing 0.065 m/s RMS, Kalman
  // 0.0002 m/s (the commanded acceleration is known exactly here, so the Kalman filter can average over a
  // long window).
  const double differencing = velocityNoise(VelocitySource::kDifferencing, 0.05, 7);
  const double kalman = velocityNoise(VelocitySource::kKalman, 0.05, 7);
  std::printf("velocity noise RMS: differencing %.4f m/s, kalman %.4f m/s, ratio %.1f\n", differencing,
              kalman, differencing / kalman);
  EXPECT_LT(kalman, differencing);
  EXPECT_GT(differencing / kalman, 100.0);
}

TEST(Navigator, PropagatesThroughAGapAndRestartsDifferencing) {
  NavigatorOptions o;
  o.velocity_source = VelocitySource::kDifferencing;
  RelativeNavigator nav(o);
  for (int k = 0; k < 20; ++k) {
    if (k > 0) nav.predict(0.1, kN, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    nav.update(Eigen::Vector3d(50.0 - 0.1 * 0.1 * k, 0.0, 0.0));
  }
  EXPECT_NEAR(nav.velocity().x(), -0.1, 1e-6);
  // A 5 s gap: the state coasts (x keeps decreasing), then the differencing restarts with the old velocity.
  const double before = nav.position().x();
  for (int k = 0; k < 50; ++k) nav.predict(0.1, kN, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  EXPECT_NEAR(nav.position().x(), before - 0.5, 0.01);
  nav.update(nav.position());
  EXPECT_NEAR(nav.velocity().x(), -0.1, 1e-3);
}
