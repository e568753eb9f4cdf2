// The noise model on rendered test geometry: each effect alone, against its configured value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "ardsim_lidar/lidar_simulator.h"
#include "test_shapes.h"

namespace ardsim_lidar {
namespace {

// Every effect off; a test switches on the one it measures.
NoiseOptions allEffectsOff() {
  NoiseOptions o;
  o.range_noise = o.incidence_cutoff = o.return_probability = o.dead_pixels = o.hot_pixels = false;
  o.background_returns = o.mixed_pixels = o.retro_reflectors = o.blooming = o.saturation = false;
  return o;
}

double standardDeviation(const std::vector<double>& values) {
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= values.size();
  double sum = 0.0;
  for (double v : values) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / (values.size() - 1));
}

TEST(NoiseModel, RangeNoiseSpreadMatchesTheConfiguredSigma) {
  NoiseOptions options = allEffectsOff();
  options.range_noise = true;
  options.range_sigma_floor_m = 0.05;
  options.range_sigma_weak_m = 0.0;
  LidarSimulator simulator(SensorOptions{}, options, 7);
  simulator.setTarget(test::makePlate(400.0));
  LidarFrame frame;
  simulator.simulate(test::facingSensor(100.0), 3, &frame);
  std::vector<double> errors;
  for (int i = 0; i < simulator.rays().size(); ++i)
    errors.push_back(frame.range_m[i] - 100.0 / simulator.rays().ray(i).z());
  EXPECT_NEAR(standardDeviation(errors), 0.05, 0.05 * 0.05);
}

// sigma = floor + weak / sqrt(s) with s = reflectivity * cos * (detection_range / range)^2: normalised by the
// sigma expected at each pixel, the errors have unit spread.
TEST(NoiseModel, RangeNoiseGrowsWithRangeAndFallsWithStrengthAsConfigured) {
  NoiseOptions options = allEffectsOff();
  options.range_noise = true;
  options.range_sigma_floor_m = 0.01;
  options.range_sigma_weak_m = 0.05;
  options.detection_range_m = 6000.0;
  const float reflectivity = 0.3f;
  LidarSimulator simulator(SensorOptions{}, options, 7);
  simulator.setTarget(test::makePlate(4000.0, reflectivity));
  for (double distance_m : {300.0, 3000.0}) {
    LidarFrame frame;
    simulator.simulate(test::facingSensor(distance_m), 1, &frame);
    std::vector<double> normalised;
    double mean_sigma_m = 0.0;
    for (int i = 0; i < simulator.rays().size(); ++i) {
      const double cos_incidence = simulator.rays().ray(i).z();
      const double range_m = distance_m / cos_incidence;
      const double s = reflectivity * cos_incidence * std::pow(6000.0 / range_m, 2);
      const double sigma_m = 0.01 + 0.05 / std::sqrt(s);
      mean_sigma_m += sigma_m / simulator.rays().size();
      normalised.push_back((frame.range_m[i] - range_m) / sigma_m);
    }
    EXPECT_NEAR(standardDeviation(normalised), 1.0, 0.05) << "at " << distance_m << " m";
    std::printf("range noise at %.0f m, reflectivity %.1f: sigma %.4f m\n", distance_m, reflectivity,
                mean_sigma_m);
  }
}

// Return fraction of a tilted plate: the mean over pixels of the configured probability 1 - exp(-s), and
// nothing beyond the incidence cut-off.
TEST(NoiseModel, DropoutFractionFollowsIncidenceAsConfigured) {
  NoiseOptions options = allEffectsOff();
  options.return_probability = true;
  options.incidence_cutoff = true;
  options.max_incidence_deg = 60.0;
  options.detection_range_m = 2000.0;
  const float reflectivity = 0.5f;
  LidarSimulator simulator(SensorOptions{}, options, 11);
  simulator.setTarget(test::makePlate(50000.0, reflectivity));
  for (double tilt_deg : {0.0, 30.0, 45.0, 55.0, 75.0}) {
    const Eigen::Isometry3d T =
        test::facingSensor(2000.0) *
        Eigen::Isometry3d(Eigen::AngleAxisd(tilt_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()));
    LidarFrame frame;
    simulator.simulate(T, 0, &frame);
    const RenderedFrame& rendered = simulator.lastRendered();
    double expected_returns = 0.0;
    int surfaces = 0;
    for (const SurfaceSample& sample : rendered.pixels) {
      if (sample.range_m <= 0.0f) continue;
      ++surfaces;
      const double incidence_deg = std::acos(sample.cos_incidence) * 180.0 / M_PI;
      const double s = reflectivity * sample.cos_incidence * std::pow(2000.0 / sample.range_m, 2);
      if (incidence_deg <= 60.0) expected_returns += 1.0 - std::exp(-s);
    }
    ASSERT_GT(surfaces, simulator.rays().size() / 2)
        << "the plate must fill most of the view at tilt " << tilt_deg;
    const double measured_fraction = static_cast<double>(frame.returnCount()) / surfaces;
    const double expected_fraction = expected_returns / surfaces;
    EXPECT_NEAR(measured_fraction, expected_fraction, 0.01) << "tilt " << tilt_deg << " deg";
    std::printf("tilt %2.0f deg: return fraction %.3f (configured %.3f)\n", tilt_deg, measured_fraction,
                expected_fraction);
    if (tilt_deg >= 75.0) {  // every ray meets the plate at more than 75 - 14 = 61 deg: beyond the cut-off
      EXPECT_EQ(frame.returnCount(), 0u);
    }
  }
}

TEST(NoiseModel, SameSeedGivesIdenticalFramesInAnyOrderAndAnotherSeedDiffers) {
  const NoiseOptions options;  // every effect on
  auto frames = [&](std::uint64_t seed, const std::vector<std::uint64_t>& indices) {
    LidarSimulator simulator(SensorOptions{}, options, seed);
    simulator.setTarget(test::makeBox(Eigen::Vector3d(3.0, 2.0, 2.5)));
    std::map<std::uint64_t, LidarFrame> result;
    for (std::uint64_t index : indices) simulator.simulate(test::facingSensor(15.0), index, &result[index]);
    return result;
  };
  auto same = [](const LidarFrame& a, const LidarFrame& b) {
    for (std::size_t i = 0; i < a.range_m.size(); ++i) {
      const bool a_nan = std::isnan(a.range_m[i]);
      if (a_nan != std::isnan(b.range_m[i]) || (!a_nan && a.range_m[i] != b.range_m[i])) return false;
    }
    return true;
  };
  auto forward = frames(42, {3, 5});
  auto backward = frames(42, {5, 3});
  auto other_seed = frames(43, {3});
  EXPECT_TRUE(same(forward[3], backward[3]));
  EXPECT_TRUE(same(forward[5], backward[5]));
  EXPECT_FALSE(same(forward[3], forward[5]));
  EXPECT_FALSE(same(forward[3], other_seed[3]));
}

TEST(NoiseModel, DeadPixelsNeverReturnAndHotPixelsAlwaysDo) {
  NoiseOptions options = allEffectsOff();
  options.dead_pixels = options.hot_pixels = true;
  options.dead_pixel_fraction = 0.01;
  options.hot_pixel_fraction = 0.005;
  LidarSimulator simulator(SensorOptions{}, options, 5);
  simulator.setTarget(test::makePlate(400.0));
  const auto& dead = simulator.noiseModel().deadPixels();
  const auto& hot = simulator.noiseModel().hotPixels();
  const double n = dead.size();
  const double dead_count = std::count(dead.begin(), dead.end(), 1);
  const double hot_count = std::count(hot.begin(), hot.end(), 1);
  EXPECT_NEAR(dead_count / n, 0.01, 0.002);
  EXPECT_NEAR(hot_count / n, 0.005, 0.0015);
  for (std::uint64_t index : {0u, 1u}) {
    LidarFrame frame;
    simulator.simulate(test::facingSensor(20.0), index, &frame);
    for (std::size_t i = 0; i < dead.size(); ++i) {
      if (dead[i]) {
        EXPECT_TRUE(std::isnan(frame.range_m[i]));
      }
      if (hot[i]) {
        EXPECT_FALSE(std::isnan(frame.range_m[i]));
      }
    }
    // Against an empty sky only the hot pixels return.
    LidarFrame sky;
    simulator.simulate(test::facingSensor(-20.0), index, &sky);
    EXPECT_EQ(sky.returnCount(), static_cast<std::size_t>(hot_count));
  }
}

TEST(NoiseModel, BackgroundReturnsAppearAtTheConfiguredRate) {
  NoiseOptions options = allEffectsOff();
  options.background_returns = true;
  options.background_probability = 0.01;
  LidarSimulator simulator(SensorOptions{}, options, 9);
  LidarFrame frame;
  std::size_t returns = 0;
  for (std::uint64_t index = 0; index < 4; ++index) {
    simulator.simulate(Eigen::Isometry3d::Identity(), index, &frame);
    returns += frame.returnCount();
  }
  const double expected = 4 * 0.01 * 256 * 256;  // 2621, standard deviation 51
  EXPECT_NEAR(static_cast<double>(returns), expected, 5 * std::sqrt(expected));
}

TEST(NoiseModel, SaturatedReturnsReadShortWithFullIntensity) {
  NoiseOptions options = allEffectsOff();
  options.saturation = true;
  options.saturation_range_m = 3.0;
  options.saturation_range_bias_m = -0.02;
  LidarSimulator simulator(SensorOptions{}, options, 1);
  simulator.setTarget(test::makePlate(40.0, 1.0f));
  LidarFrame frame;
  simulator.simulate(test::facingSensor(1.0), 0, &frame);
  const int centre = 128 * 256 + 128;
  EXPECT_FLOAT_EQ(frame.intensity[centre], 1.0f);
  EXPECT_NEAR(frame.range_m[centre], 1.0 / simulator.rays().ray(centre).z() - 0.02, 1e-4);
  simulator.simulate(test::facingSensor(10.0), 0, &frame);  // not saturated: (3/10)^2 = 0.09
  // intensity = reflectivity * cos * (saturation_range / range)^2 with range = 10 / cos
  EXPECT_NEAR(frame.intensity[centre], 0.09 * std::pow(simulator.rays().ray(centre).z(), 3), 1e-4);
  EXPECT_NEAR(frame.range_m[centre], 10.0 / simulator.rays().ray(centre).z(), 1e-4);
}

// A retro-reflector patch 0.5 m in front of a dark plate at 30 m: strong, saturated returns that bloom into
// the neighbouring pixels.
TEST(NoiseModel, RetroReflectorsReturnStronglyAndBloom) {
  ardsim_description::TriangleMesh mesh = test::makePlate(100.0, 0.1f);
  mesh.materials.push_back(test::material(0.8f, true));
  Eigen::Isometry3d in_front = Eigen::Isometry3d::Identity();
  in_front.translation().z() = 0.5;
  test::addPlate(&mesh, 0.3, in_front, 1);
  auto countRetroPixels = [&](bool blooming) {
    NoiseOptions options = allEffectsOff();
    options.retro_reflectors = true;
    options.blooming = blooming;
    LidarSimulator simulator(SensorOptions{}, options, 3);
    simulator.setTarget(mesh);
    LidarFrame frame;
    simulator.simulate(test::facingSensor(30.0), 0, &frame);
    int near_count = 0;
    for (std::size_t i = 0; i < frame.range_m.size(); ++i) {
      if (frame.range_m[i] < 29.8) {
        ++near_count;
        if (!blooming) {
          EXPECT_FLOAT_EQ(frame.intensity[i], 1.0f);
        }
      }
    }
    return near_count;
  };
  const int footprint = countRetroPixels(false);
  EXPECT_GT(footprint, 30);                           // 0.3 m at 29.5 m: about 7 x 7 pixels
  EXPECT_GT(countRetroPixels(true), footprint + 20);  // about 40 expected within 2 pixels
}

// A box in front of a plate: flying pixels between the two depths appear only with mixed pixels on.
TEST(NoiseModel, MixedPixelsFillDepthEdgesWithIntermediateRanges) {
  ardsim_description::TriangleMesh mesh = test::makePlate(100.0);
  Eigen::Isometry3d in_front = Eigen::Isometry3d::Identity();
  in_front.translation().z() = 5.0;
  test::addPlate(&mesh, 3.0, in_front, 0);
  auto countBetween = [&](bool mixed) {
    NoiseOptions options = allEffectsOff();
    options.mixed_pixels = mixed;
    options.mixed_pixel_probability = 1.0;
    LidarSimulator simulator(SensorOptions{}, options, 3);
    simulator.setTarget(mesh);
    LidarFrame frame;
    simulator.simulate(test::facingSensor(25.0), 0, &frame);
    int between = 0;
    for (int i = 0; i < simulator.rays().size(); ++i) {
      const double along_boresight_m = frame.range_m[i] * simulator.rays().ray(i).z();
      if (along_boresight_m > 20.05 && along_boresight_m < 24.95) ++between;
    }
    return between;
  };
  EXPECT_EQ(countBetween(false), 0);
  EXPECT_GT(countBetween(true),
            400);  // the square spans about 110 pixels: its outline is about 2 x 440 pixels
}

TEST(NoiseModel, BadOptionsAreRejectedNamingTheParameter) {
  NoiseOptions options;
  options.max_incidence_deg = 120.0;
  try {
    validate(options);
    FAIL() << "max_incidence_deg 120 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("noise/max_incidence_deg = 120"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ardsim_lidar
