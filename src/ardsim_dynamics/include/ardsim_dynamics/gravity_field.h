// Earth gravity by spherical harmonics, evaluated in the Earth-fixed frame with the Cunningham /
// Montenbruck-Gill V/W recursion (Montenbruck & Gill, Satellite Orbits, sec. 3.2.4-3.2.5). ROS-free.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace ardsim_dynamics {

class GravityModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class GravityField {
 public:
  // Point-mass field (degree 0) of the given GM and reference radius, room for coefficients up to max_degree.
  GravityField(double gm_m3_s2, double reference_radius_m, int max_degree);

  // Reads a coefficient file: '#' comment lines, header lines '# GM = value' and '# R = value', rows 'n m C
  // S' of fully normalized coefficients. Throws GravityModelError with the file name and line number on any
  // problem.
  static GravityField fromFile(const std::string& path);
  // The EGM96 13x13 table shipped with the package (data/egm96_13x13.txt).
  static GravityField egm96();
  static std::string egm96Path();

  // Sets a fully normalized coefficient (n >= 2, 0 <= m <= n <= maxDegree()).
  void setNormalizedCoefficient(int n, int m, double c_bar, double s_bar);
  double normalizedC(int n, int m) const;
  double normalizedS(int n, int m) const;

  // Acceleration (m/s^2, Earth-fixed) at an Earth-fixed position (m), summing degrees and orders 0..degree.
  // degree must be in [0, maxDegree()].
  Eigen::Vector3d acceleration(const Eigen::Vector3d& r_ecef_m, int degree) const;

  double gm() const { return gm_; }
  double referenceRadius() const { return radius_; }
  int maxDegree() const { return max_degree_; }

 private:
  int index(int n, int m) const { return n * (max_degree_ + 1) + m; }

  double gm_;
  double radius_;
  int max_degree_;
  // Unnormalized coefficients (the recursion's convention); fine up to degree 13 in double.
  std::vector<double> c_;
  std::vector<double> s_;
  std::vector<double> normalization_;  // N_nm: C_nm = Cbar_nm * N_nm
};

}  // namespace ardsim_dynamics
