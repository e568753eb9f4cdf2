// gravity_eval [--model FILE] --degree N X Y Z
// Prints the gravitational acceleration "ax ay az" (m/s^2, Earth-fixed, full precision) at the Earth-fixed
// position X Y Z (m). Without --model the shipped EGM96 13x13 table is used. Errors: one line on stderr,
// exit 2.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "ardsim_dynamics/gravity_field.h"

namespace {

constexpr const char* kUsage = "usage: gravity_eval [--model FILE] --degree N X Y Z";

[[noreturn]] void die(const std::string& message) {
  std::cerr << "gravity_eval: " << message << "\n";
  std::exit(2);
}

double parseNumber(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') die(what + " '" + text + "' is not a number (" + kUsage + ")");
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  std::string model_path;
  int degree = -1;
  std::vector<double> position;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--model" || arg == "--degree") {
      if (i + 1 >= argc) die(arg + " needs a value (" + std::string(kUsage) + ")");
      const std::string value = argv[++i];
      if (arg == "--model") {
        model_path = value;
      } else {
        const double d = parseNumber(value, "degree");
        if (d < 0 || d != static_cast<int>(d)) die("degree '" + value + "' is not a non-negative integer");
        degree = static_cast<int>(d);
      }
    } else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage << "\n";
      return 0;
    } else {
      position.push_back(parseNumber(arg, "coordinate"));
    }
  }
  if (degree < 0) die(std::string("--degree is required (") + kUsage + ")");
  if (position.size() != 3) die("expected three coordinates X Y Z in metres (" + std::string(kUsage) + ")");
  const Eigen::Vector3d r(position[0], position[1], position[2]);
  if (r.norm() < 1.0) die("position is at the Earth's centre");
  try {
    const ardsim_dynamics::GravityField field = model_path.empty()
                                                    ? ardsim_dynamics::GravityField::egm96()
                                                    : ardsim_dynamics::GravityField::fromFile(model_path);
    if (degree > field.maxDegree())
      die("degree " + std::to_string(degree) + " is above the model's maximum degree " +
          std::to_string(field.maxDegree()));
    const Eigen::Vector3d a = field.acceleration(r, degree);
    std::printf("%.17g %.17g %.17g\n", a.x(), a.y(), a.z());
  } catch (const ardsim_dynamics::GravityModelError& e) {
    die(e.what());
  }
  return 0;
}
