#include "ardsim_dynamics/gravity_field.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace ardsim_dynamics {
namespace {

// N_nm = sqrt((2 - delta_0m) (2n + 1) (n - m)! / (n + m)!)
double normalizationFactor(int n, int m) {
  double ratio = 1.0;  // (n - m)! / (n + m)!
  for (int k = n - m + 1; k <= n + m; ++k) ratio /= k;
  return std::sqrt((m == 0 ? 1.0 : 2.0) * (2 * n + 1) * ratio);
}

}  // namespace

GravityField::GravityField(double gm_m3_s2, double reference_radius_m, int max_degree)
    : gm_(gm_m3_s2), radius_(reference_radius_m), max_degree_(max_degree) {
  if (max_degree < 0) throw GravityModelError("max degree " + std::to_string(max_degree) + " is negative");
  const int size = (max_degree + 1) * (max_degree + 1);
  c_.assign(size, 0.0);
  s_.assign(size, 0.0);
  normalization_.assign(size, 0.0);
  for (int n = 0; n <= max_degree; ++n)
    for (int m = 0; m <= n; ++m) normalization_[index(n, m)] = normalizationFactor(n, m);
  c_[index(0, 0)] = 1.0;
}

void GravityField::setNormalizedCoefficient(int n, int m, double c_bar, double s_bar) {
  if (n < 2 || m < 0 || m > n || n > max_degree_)
    throw GravityModelError("coefficient (" + std::to_string(n) + ", " + std::to_string(m) +
                            ") outside degree 2.." + std::to_string(max_degree_) + ", order 0..n");
  c_[index(n, m)] = c_bar * normalization_[index(n, m)];
  s_[index(n, m)] = s_bar * normalization_[index(n, m)];
}

double GravityField::normalizedC(int n, int m) const {
  return c_[index(n, m)] / normalization_[index(n, m)];
}
double GravityField::normalizedS(int n, int m) const {
  return s_[index(n, m)] / normalization_[index(n, m)];
}

GravityField GravityField::fromFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw GravityModelError("cannot read gravity model file '" + path + "'");
  double gm = 0.0, radius = 0.0;
  struct Row {
    int n, m;
    double c, s;
  };
  std::vector<Row> rows;
  int max_degree = 0;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (line[first] == '#') {
      std::istringstream header(line.substr(first + 1));
      std::string key, eq;
      double value;
      if (header >> key >> eq >> value && eq == "=") {
        if (key == "GM") gm = value;
        if (key == "R") radius = value;
      }
      continue;
    }
    std::istringstream fields(line);
    Row row{};
    if (!(fields >> row.n >> row.m >> row.c >> row.s) || row.n < 2 || row.m < 0 || row.m > row.n)
      throw GravityModelError(path + ":" + std::to_string(line_no) +
                              ": expected 'n m C S' with n >= 2, 0 <= m <= n");
    max_degree = std::max(max_degree, row.n);
    rows.push_back(row);
  }
  if (!(gm > 0.0) || !(radius > 0.0))
    throw GravityModelError(path + ": missing or non-positive '# GM = ...' or '# R = ...' header line");
  GravityField field(gm, radius, max_degree);
  for (const Row& row : rows) field.setNormalizedCoefficient(row.n, row.m, row.c, row.s);
  return field;
}

std::string GravityField::egm96Path() {
  return std::string(ARDSIM_DYNAMICS_DATA_DIR) + "/egm96_13x13.txt";
}

GravityField GravityField::egm96() {
  static const GravityField field = fromFile(egm96Path());
  return field;
}

Eigen::Vector3d GravityField::acceleration(const Eigen::Vector3d& r, int degree) const {
  if (degree < 0 || degree > max_degree_)
    throw GravityModelError("degree " + std::to_string(degree) + " outside 0.." +
                            std::to_string(max_degree_));
  // V_nm, W_nm up to degree + 1 (the acceleration of degree n needs terms of degree n + 1).
  constexpr int kMaxDim = 32;
  const int dim = degree + 2;
  if (dim > kMaxDim)
    throw GravityModelError("degree " + std::to_string(degree) + " too high for this evaluator");
  double V[kMaxDim][kMaxDim];
  double W[kMaxDim][kMaxDim];

  const double r2 = r.squaredNorm();
  const double rho = radius_ * radius_ / r2;
  const double x0 = radius_ * r.x() / r2;
  const double y0 = radius_ * r.y() / r2;
  const double z0 = radius_ * r.z() / r2;

  // Zonal terms V_n0 (W_n0 = 0).
  V[0][0] = radius_ / std::sqrt(r2);
  W[0][0] = 0.0;
  V[1][0] = z0 * V[0][0];
  W[1][0] = 0.0;
  for (int n = 2; n < dim; ++n) {
    V[n][0] = ((2 * n - 1) * z0 * V[n - 1][0] - (n - 1) * rho * V[n - 2][0]) / n;
    W[n][0] = 0.0;
  }
  // Tesseral and sectorial terms.
  for (int m = 1; m < dim; ++m) {
    V[m][m] = (2 * m - 1) * (x0 * V[m - 1][m - 1] - y0 * W[m - 1][m - 1]);
    W[m][m] = (2 * m - 1) * (x0 * W[m - 1][m - 1] + y0 * V[m - 1][m - 1]);
    if (m + 1 < dim) {
      V[m + 1][m] = (2 * m + 1) * z0 * V[m][m];
      W[m + 1][m] = (2 * m + 1) * z0 * W[m][m];
    }
    for (int n = m + 2; n < dim; ++n) {
      V[n][m] = ((2 * n - 1) * z0 * V[n - 1][m] - (n + m - 1) * rho * V[n - 2][m]) / (n - m);
      W[n][m] = ((2 * n - 1) * z0 * W[n - 1][m] - (n + m - 1) * rho * W[n - 2][m]) / (n - m);
    }
  }

  double ax = 0.0, ay = 0.0, az = 0.0;
  for (int m = 0; m <= degree; ++m) {
    for (int n = m; n <= degree; ++n) {
      const double C = c_[index(n, m)];
      const double S = s_[index(n, m)];
      if (m == 0) {
        ax -= C * V[n + 1][1];
        ay -= C * W[n + 1][1];
        az -= (n + 1) * C * V[n + 1][0];
      } else {
        const double fac = 0.5 * (n - m + 1) * (n - m + 2);
        ax += 0.5 * (-C * V[n + 1][m + 1] - S * W[n + 1][m + 1]) +
              fac * (C * V[n + 1][m - 1] + S * W[n + 1][m - 1]);
        ay += 0.5 * (-C * W[n + 1][m + 1] + S * V[n + 1][m + 1]) +
              fac * (-C * W[n + 1][m - 1] + S * V[n + 1][m - 1]);
        az += (n - m + 1) * (-C * V[n + 1][m] - S * W[n + 1][m]);
      }
    }
  }
  return (gm_ / (radius_ * radius_)) * Eigen::Vector3d(ax, ay, az);
}

}  // namespace ardsim_dynamics
