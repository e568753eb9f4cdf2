// Gravity field and orbit propagation: two-body conservation, J2 nodal regression, 13x13 against an
// independent evaluation of the potential, coefficient-file errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <vector>

#include "ardsim_dynamics/gravity_field.h"
#include "ardsim_dynamics/orbit.h"
#include "ardsim_dynamics/vehicle_dynamics.h"

using namespace ardsim_dynamics;

namespace {

EnvironmentOptions inertialOnly(int degree) {
  EnvironmentOptions o;
  o.gravity_degree = degree;
  o.atmosphere_density_kgm3 = 0.0;
  o.earth_rotation = false;
  o.gravity_gradient_torque = false;
  return o;
}

VehicleState issLikeState() {
  KeplerianElements e;
  e.semi_major_axis_m = 6793137.0;
  e.eccentricity = 0.0005;
  e.inclination_rad = 51.64 * M_PI / 180.0;
  e.raan_rad = 0.3;
  e.arg_perigee_rad = 0.2;
  const CartesianState c = keplerianToCartesian(e);
  VehicleState s;
  s.position_m = c.position_m;
  s.velocity_mps = c.velocity_mps;
  return s;
}

// Potential of a fully normalized field, summed independently of the V/W recursion: normalized associated
// Legendre functions by the standard column recursion, in long double.
long double potential(const GravityField& f, int degree, const Eigen::Vector3d& r_in) {
  const long double x = r_in.x(), y = r_in.y(), z = r_in.z();
  const long double r = std::sqrt(x * x + y * y + z * z);
  const long double sin_phi = z / r, cos_phi = std::sqrt(x * x + y * y) / r;
  const long double lambda = std::atan2(y, x);
  const int N = degree;
  std::vector<std::vector<long double>> P(N + 1, std::vector<long double>(N + 1, 0.0L));
  P[0][0] = 1.0L;
  if (N >= 1) P[1][1] = std::sqrt(3.0L) * cos_phi;
  for (int m = 2; m <= N; ++m)
    P[m][m] = std::sqrt((2.0L * m + 1.0L) / (2.0L * m)) * cos_phi * P[m - 1][m - 1];
  for (int m = 0; m < N; ++m) P[m + 1][m] = std::sqrt(2.0L * m + 3.0L) * sin_phi * P[m][m];
  for (int m = 0; m <= N; ++m)
    for (int n = m + 2; n <= N; ++n) {
      const long double a = std::sqrt((2.0L * n - 1) * (2.0L * n + 1) / ((n - m) * (long double)(n + m)));
      const long double b = std::sqrt((2.0L * n + 1) * (n + m - 1) * (long double)(n - m - 1) /
                                      ((n - m) * (long double)(n + m) * (2.0L * n - 3)));
      P[n][m] = a * sin_phi * P[n - 1][m] - b * P[n - 2][m];
    }
  long double sum = 1.0L;  // C00
  const long double R = f.referenceRadius();
  for (int n = 2; n <= N; ++n) {
    long double inner = 0.0L;
    for (int m = 0; m <= n; ++m)
      inner +=
          P[n][m] * (f.normalizedC(n, m) * std::cos(m * lambda) + f.normalizedS(n, m) * std::sin(m * lambda));
    sum += std::pow(R / r, (long double)n) * inner;
  }
  return f.gm() / r * sum;
}

}  // namespace

TEST(Gravity, ShippedTableLoadsWithItsHeader) {
  const GravityField f = GravityField::egm96();
  EXPECT_EQ(f.maxDegree(), 13);
  EXPECT_DOUBLE_EQ(f.gm(), 3.986004415e14);
  EXPECT_DOUBLE_EQ(f.referenceRadius(), 6378136.3);
  EXPECT_DOUBLE_EQ(f.normalizedC(2, 0), -4.84165371736e-04);
  EXPECT_DOUBLE_EQ(f.normalizedS(13, 13), f.normalizedS(13, 13));
}

TEST(Gravity, PointMassIsGmOverRSquared) {
  const GravityField f = GravityField::egm96();
  const Eigen::Vector3d r(1e6, -6.5e6, 2e6);
  const Eigen::Vector3d a = f.acceleration(r, 0);
  EXPECT_NEAR((a + f.gm() / std::pow(r.norm(), 3) * r).norm(), 0.0, 1e-12);
}

TEST(Gravity, Degree13MatchesFiniteDifferencesOfThePotential) {
  const GravityField f = GravityField::egm96();
  const std::vector<Eigen::Vector3d> positions = {{6793137.0, 0.0, 0.0},
                                                  {1.2e6, -5.1e6, 4.3e6},
                                                  {-3.0e6, 2.0e6, -5.9e6},
                                                  {100.0, 200.0, 6.9e6},
                                                  {4.0e6, 4.0e6, 3.0e6}};
  for (const Eigen::Vector3d& r : positions) {
    const Eigen::Vector3d a = f.acceleration(r, 13);
    Eigen::Vector3d fd;
    const double h = 5.0;
    for (int i = 0; i < 3; ++i) {
      auto U = [&](double k) {
        Eigen::Vector3d p = r;
        p[i] += k * h;
        return potential(f, 13, p);
      };
      // 4th-order central difference, in long double so that rounding stays far below the 1e-8 tolerance.
      fd[i] = static_cast<double>((-U(2) + 8.0L * U(1) - 8.0L * U(-1) + U(-2)) / (12.0L * h));
    }
    EXPECT_LT((a - fd).norm(), 1e-8) << "at " << r.transpose() << ": " << a.transpose() << " vs "
                                     << fd.transpose();
    // The non-central part is what the test is about: make sure it is there (J2 alone is ~1e-2 m/s^2).
    EXPECT_GT((a - f.acceleration(r, 0)).norm(), 1e-3);
  }
}

TEST(Gravity, LowerDegreesDiffer) {
  const GravityField f = GravityField::egm96();
  const Eigen::Vector3d r(1.2e6, -5.1e6, 4.3e6);
  EXPECT_GT((f.acceleration(r, 13) - f.acceleration(r, 12)).norm(), 1e-9);
  EXPECT_THROW(f.acceleration(r, 14), GravityModelError);
}

TEST(Gravity, FileErrorsNameTheFileAndLine) {
  EXPECT_THROW(GravityField::fromFile("/nonexistent/gravity.txt"), GravityModelError);
  const std::string path = ::testing::TempDir() + "/bad_gravity.txt";
  {
    std::ofstream out(path);
    out << "# GM = 3.986004415e14\n# R = 6378136.3\n 2 0 -4.8e-4 0\n 3 x 1 2\n";
  }
  try {
    GravityField::fromFile(path);
    FAIL() << "a malformed row must be rejected";
  } catch (const GravityModelError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":4"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << " 2 0 -4.8e-4 0\n";
  }
  EXPECT_THROW(GravityField::fromFile(path), GravityModelError);  // no GM / R header
}

TEST(Orbits, TwoBodyConservesEnergyAndAngularMomentumOverTenOrbits) {
  const Environment env(GravityField::egm96(), inertialOnly(0));
  VehicleProperties vehicle;
  VehicleState s = issLikeState();
  const double gm = env.field().gm();
  auto energy = [&](const VehicleState& v) {
    return 0.5 * v.velocity_mps.squaredNorm() - gm / v.position_m.norm();
  };
  const double e0 = energy(s);
  const Eigen::Vector3d h0 = s.position_m.cross(s.velocity_mps);
  const double period = 2.0 * M_PI * std::sqrt(std::pow(6793137.0, 3) / gm);
  const double dt = 1.0;
  const int steps = static_cast<int>(10.0 * period / dt);
  double max_energy_error = 0.0, max_h_error = 0.0;
  for (int k = 0; k < steps; ++k) {
    s = rk4Step(env, vehicle, s, BodyWrench{}, k * dt, dt);
    max_energy_error = std::max(max_energy_error, std::abs((energy(s) - e0) / e0));
    max_h_error = std::max(max_h_error, (s.position_m.cross(s.velocity_mps) - h0).norm() / h0.norm());
  }
  RecordProperty("max_relative_energy_error", std::to_string(max_energy_error));
  EXPECT_LT(max_energy_error, 1e-9);
  EXPECT_LT(max_h_error, 1e-9);
}

TEST(Orbits, J2NodalRegressionMatchesTheAnalyticRate) {
  const GravityField egm = GravityField::egm96();
  GravityField j2_only(egm.gm(), egm.referenceRadius(), 2);
  j2_only.setNormalizedCoefficient(2, 0, egm.normalizedC(2, 0), 0.0);
  const Environment env(j2_only, inertialOnly(2));
  VehicleProperties vehicle;
  VehicleState s = issLikeState();
  const double gm = egm.gm(), a = 6793137.0, e = 0.0005, i = 51.64 * M_PI / 180.0;
  const double j2 = -egm.normalizedC(2, 0) * std::sqrt(5.0);
  const double n = std::sqrt(gm / (a * a * a));
  const double p = a * (1.0 - e * e);
  const double analytic_rate = -1.5 * n * j2 * std::pow(egm.referenceRadius() / p, 2) * std::cos(i);

  // RAAN at each ascending node, then a least-squares slope: nodal crossings remove most short-period terms.
  std::vector<double> times, raans;
  const double dt = 2.0;
  const int steps = static_cast<int>(10.0 * 2.0 * M_PI / n / dt) + 10;
  for (int k = 0; k < steps; ++k) {
    const VehicleState next = rk4Step(env, vehicle, s, BodyWrench{}, k * dt, dt);
    if (s.position_m.z() < 0.0 && next.position_m.z() >= 0.0) {
      const double frac = -s.position_m.z() / (next.position_m.z() - s.position_m.z());
      const Eigen::Vector3d h = next.position_m.cross(next.velocity_mps);
      times.push_back((k + frac) * dt);
      raans.push_back(std::atan2(h.x(), -h.y()));
    }
    s = next;
  }
  ASSERT_GE(times.size(), 9u);
  double mt = 0, mr = 0;
  for (size_t k = 0; k < times.size(); ++k) mt += times[k] / times.size(), mr += raans[k] / times.size();
  double num = 0, den = 0;
  for (size_t k = 0; k < times.size(); ++k)
    num += (times[k] - mt) * (raans[k] - mr), den += std::pow(times[k] - mt, 2);
  const double measured_rate = num / den;
  RecordProperty("nodal_rate_ratio", std::to_string(measured_rate / analytic_rate));
  EXPECT_NEAR(measured_rate / analytic_rate, 1.0, 0.01) << measured_rate << " vs analytic " << analytic_rate;
}
