// Two independent geometry paths, the EGL rasteriser and Embree's ray caster, must give the same range image.
#include <gtest/gtest.h>

#include <cmath>

#include "ardsim_description/models.h"
#include "ardsim_lidar/docking_views.h"
#include "ardsim_lidar/egl_renderer.h"
#include "ardsim_lidar/embree_ray_caster.h"
#include "test_shapes.h"

namespace ardsim_lidar {

// Compares two frames pixel by pixel; returns the fraction of pixels that disagree (hit versus miss, or range
// different by more than tolerance_m). Silhouette and occlusion edges may differ where a pixel centre lies
// exactly on an edge, so a few disagreeing pixels are allowed by the callers.
double disagreement(const RenderedFrame& a, const RenderedFrame& b, double tolerance_m, int* both_hit) {
  int differing = 0;
  *both_hit = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const bool hit_a = a.pixels[i].range_m > 0.0f;
    const bool hit_b = b.pixels[i].range_m > 0.0f;
    if (hit_a != hit_b) {
      ++differing;
    } else if (hit_a) {
      ++*both_hit;
      if (std::abs(a.pixels[i].range_m - b.pixels[i].range_m) > tolerance_m ||
          std::abs(a.pixels[i].cos_incidence - b.pixels[i].cos_incidence) > 1e-3 ||
          a.pixels[i].material != b.pixels[i].material)
        ++differing;
    }
  }
  return static_cast<double>(differing) / a.pixels.size();
}

namespace {

TEST(EmbreeAgreement, BoxInFrontOfPlateGivesTheSameRangeImage) {
  ardsim_description::TriangleMesh mesh = test::makeBox(Eigen::Vector3d(2.0, 1.0, 1.5));
  mesh.materials.push_back(test::material(0.2f));
  Eigen::Isometry3d behind = Eigen::Isometry3d::Identity();
  behind.translation().z() = -4.0;
  test::addPlate(&mesh, 12.0, behind, 1);
  const SensorOptions sensor;
  EglRenderer renderer(sensor);
  renderer.setMesh(mesh);
  const EmbreeRayCaster caster(sensor, mesh);
  Eigen::Isometry3d T = test::facingSensor(14.0);
  T.linear() = T.linear() * Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  RenderedFrame rasterised;
  RenderedFrame ray_cast;
  renderer.render(T, &rasterised);
  caster.cast(T, &ray_cast);
  int both_hit = 0;
  EXPECT_LT(disagreement(rasterised, ray_cast, 1e-3, &both_hit), 0.002);
  EXPECT_GT(both_hit, 20000);
}

// The ISS from the docking axis, as in bench_lidar: the two range images agree pixel by pixel.
TEST(EmbreeAgreement, IssFromTheDockingAxisGivesTheSameRangeImage) {
  const ardsim_description::TriangleMesh mesh = ardsim_description::buildIss();
  const SensorOptions sensor;
  EglRenderer renderer(sensor);
  renderer.setMesh(mesh);
  const EmbreeRayCaster caster(sensor, mesh);
  for (double range_m : {100.0, 30.0, 10.0, 3.0}) {
    const Eigen::Isometry3d T = lidarOnDockingAxis(ardsim_description::TargetKind::kIss, range_m);
    RenderedFrame rasterised;
    RenderedFrame ray_cast;
    renderer.render(T, &rasterised);
    caster.cast(T, &ray_cast);
    int both_hit = 0;
    const double fraction = disagreement(rasterised, ray_cast, 1e-3, &both_hit);
    EXPECT_LT(fraction, 0.005) << "at " << range_m << " m";
    EXPECT_GT(both_hit, 10000) << "at " << range_m << " m";
    std::printf("ISS at %5.1f m: %d pixels hit by both, %.4f %% disagree\n", range_m, both_hit,
                100.0 * fraction);
  }
}

}  // namespace
}  // namespace ardsim_lidar
