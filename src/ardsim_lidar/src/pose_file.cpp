#include "ardsim_lidar/pose_file.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace ardsim_lidar {

namespace {

bool parseNumber(const std::string& field, double* value) {
  char* end = nullptr;
  *value = std::strtod(field.c_str(), &end);
  return !field.empty() && end == field.c_str() + field.size();
}

}  // namespace

void parsePoses(std::istream& input, std::vector<PoseRow>* poses, std::vector<PoseRowError>* errors) {
  std::string line;
  int line_number = 0;
  bool seen_data_line = false;
  while (std::getline(input, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    for (char& c : line)
      if (c == ',' || c == '\t') c = ' ';
    std::istringstream stream(line);
    std::vector<std::string> fields;
    for (std::string field; stream >> field;) fields.push_back(field);
    if (fields.empty() || fields.front().front() == '#') continue;

    std::vector<double> values;
    std::string bad_field;
    for (const std::string& field : fields) {
      double value = 0.0;
      if (!parseNumber(field, &value)) {
        bad_field = field;
        break;
      }
      values.push_back(value);
    }
    const bool first = !seen_data_line;
    seen_data_line = true;
    if (!bad_field.empty()) {
      if (first && values.empty()) continue;  // header line
      errors->push_back({line_number, "'" + bad_field + "' is not a number"});
      continue;
    }
    if (values.size() != 7) {
      errors->push_back(
          {line_number, "expected 7 fields (x y z qx qy qz qw), found " + std::to_string(values.size())});
      continue;
    }
    bool finite = true;
    for (double value : values) finite = finite && std::isfinite(value);
    if (!finite) {
      errors->push_back({line_number, "non-finite value"});
      continue;
    }
    const Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      errors->push_back({line_number, "quaternion norm " + std::to_string(q.norm()) + " is not 1"});
      continue;
    }
    PoseRow row;
    row.line_number = line_number;
    row.T_lidar_target.linear() = q.normalized().toRotationMatrix();
    row.T_lidar_target.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
    poses->push_back(row);
  }
}

}  // namespace ardsim_lidar
