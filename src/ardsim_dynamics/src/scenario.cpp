#include "ardsim_dynamics/scenario.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>
#include <Eigen/Eigenvalues>

namespace ardsim_dynamics {
namespace {

constexpr double kDeg = M_PI / 180.0;

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "(empty)";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  std::ostringstream out;
  out << YAML::Dump(node);
  std::string text = out.str();
  for (char& c : text)
    if (c == '\n') c = ' ';
  return text;
}

// Reads one YAML map, naming every key by its full path in errors, and rejects keys it was not asked for
// (typos).
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string path, std::string source)
      : node_(node), path_(std::move(path)), source_(std::move(source)) {
    if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap())
      fail(path_.empty() ? "(top level)" : path_, describe(node_), "a map of keys");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& value, const std::string& allowed) const {
    throw ScenarioError(source_ + ": key '" + key + "' = " + value + ": allowed " + allowed);
  }

  std::string key(const std::string& name) const { return path_.empty() ? name : path_ + "." + name; }

  YAML::Node get(const std::string& name) {
    used_.insert(name);
    return node_.IsMap() ? node_[name] : YAML::Node();
  }

  MapReader child(const std::string& name) { return MapReader(get(name), key(name), source_); }

  void number(const std::string& name, double& value, double min, double max, bool min_open = false) {
    const YAML::Node n = get(name);
    if (!n.IsDefined() || n.IsNull()) return;
    double v = 0.0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(key(name), describe(n), rangeText(min, max, min_open));
    }
    if (!std::isfinite(v) || v > max || v < min || (min_open && v == min))
      fail(key(name), describe(n), rangeText(min, max, min_open));
    value = v;
  }

  void angleDeg(const std::string& name, double& value_rad, double min_deg, double max_deg) {
    double deg = value_rad / kDeg;
    number(name, deg, min_deg, max_deg);
    value_rad = deg * kDeg;
  }

  void integer(const std::string& name, int& value, int min, int max) {
    double v = value;
    number(name, v, min, max);
    if (v != std::floor(v))
      fail(key(name), describe(get(name)), "an integer in [" + fmt(min) + ", " + fmt(max) + "]");
    value = static_cast<int>(v);
  }

  void boolean(const std::string& name, bool& value) {
    const YAML::Node n = get(name);
    if (!n.IsDefined() || n.IsNull()) return;
    try {
      value = n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(key(name), describe(n), "true or false");
    }
  }

  void text(const std::string& name, std::string& value) {
    const YAML::Node n = get(name);
    if (!n.IsDefined() || n.IsNull()) return;
    if (!n.IsScalar()) fail(key(name), describe(n), "a string");
    value = n.Scalar();
  }

  void vector3(const std::string& name, Eigen::Vector3d& value, double min, double max, double scale = 1.0) {
    const YAML::Node n = get(name);
    if (!n.IsDefined() || n.IsNull()) return;
    const std::string allowed = "a list of 3 numbers in " + rangeText(min, max, false);
    if (!n.IsSequence() || n.size() != 3) fail(key(name), describe(n), allowed);
    for (int i = 0; i < 3; ++i) {
      double v = 0.0;
      try {
        v = n[i].as<double>();
      } catch (const YAML::Exception&) {
        fail(key(name), describe(n), allowed);
      }
      if (!std::isfinite(v) || v < min || v > max) fail(key(name), describe(n), allowed);
      value[i] = v * scale;
    }
  }

  void matrix3(const std::string& name, Eigen::Matrix3d& value) {
    const YAML::Node n = get(name);
    if (!n.IsDefined() || n.IsNull()) return;
    const std::string allowed = "3 rows of 3 finite numbers";
    if (!n.IsSequence() || n.size() != 3) fail(key(name), describe(n), allowed);
    for (int r = 0; r < 3; ++r) {
      if (!n[r].IsSequence() || n[r].size() != 3) fail(key(name), describe(n), allowed);
      for (int c = 0; c < 3; ++c) {
        try {
          value(r, c) = n[r][c].as<double>();
        } catch (const YAML::Exception&) {
          fail(key(name), describe(n), allowed);
        }
        if (!std::isfinite(value(r, c))) fail(key(name), describe(n), allowed);
      }
    }
  }

  // Rejects keys nobody asked for: a misspelt key must not silently fall back to a default.
  void finish() const {
    if (!node_.IsMap()) return;
    for (const auto& item : node_) {
      const std::string name = item.first.as<std::string>();
      if (!used_.count(name)) {
        std::string known;
        for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
        fail(key(name), describe(item.second), "keys here are: " + known);
      }
    }
  }

 private:
  static std::string fmt(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
  }
  static std::string rangeText(double min, double max, bool min_open) {
    return std::string(min_open ? "(" : "[") + fmt(min) + ", " + fmt(max) + "]";
  }

  YAML::Node node_;
  std::string path_;
  std::string source_;
  std::set<std::string> used_;
};

void readVehicle(MapReader& r, VehicleProperties& v) {
  r.number("mass_kg", v.mass_kg, 0.0, 1e7, true);
  r.matrix3("inertia_kgm2", v.inertia_kgm2);
  const Eigen::Matrix3d I = v.inertia_kgm2;
  if ((I - I.transpose()).norm() > 1e-9 * I.norm() ||
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I).eigenvalues().minCoeff() <= 0.0)
    r.fail(r.key("inertia_kgm2"), "(matrix given)", "a symmetric positive-definite matrix");
  r.number("drag_area_m2", v.drag_area_m2, 0.0, 1e5);
  r.number("drag_coefficient", v.drag_coefficient, 0.0, 10.0);
}

}  // namespace

std::uint64_t Scenario::seed(const std::string& name) const {
  const auto it = seeds.find(name);
  return it == seeds.end() ? 0 : it->second;
}

Eigen::Matrix3d rotationFromRollPitchYaw(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Scenario parseScenario(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ScenarioError(source + ": not valid YAML: " + e.what());
  }
  Scenario s;
  s.source_path = source;
  MapReader top(root, "", source);
  top.text("name", s.name);

  MapReader target = top.child("target");
  std::string kind = "iss";
  target.text("kind", kind);
  try {
    s.target_kind = ardsim_description::parseTargetKind(kind);
  } catch (const std::invalid_argument&) {
    target.fail("target.kind", "'" + kind + "'", "iss or hubble");
  }
  MapReader orbit = target.child("orbit");
  orbit.number("semi_major_axis_m", s.target_orbit.semi_major_axis_m, 6.5e6, 5e7);
  orbit.number("eccentricity", s.target_orbit.eccentricity, 0.0, 0.1);
  orbit.angleDeg("inclination_deg", s.target_orbit.inclination_rad, 0.0, 180.0);
  orbit.angleDeg("raan_deg", s.target_orbit.raan_rad, -360.0, 360.0);
  orbit.angleDeg("arg_perigee_deg", s.target_orbit.arg_perigee_rad, -360.0, 360.0);
  orbit.angleDeg("true_anomaly_deg", s.target_orbit.true_anomaly_rad, -360.0, 360.0);
  orbit.finish();
  if (s.target_orbit.semi_major_axis_m * (1.0 - s.target_orbit.eccentricity) < 6.5e6)
    orbit.fail("target.orbit",
               "perigee radius " +
                   std::to_string(s.target_orbit.semi_major_axis_m * (1.0 - s.target_orbit.eccentricity)),
               "perigee radius >= 6.5e6 m (above the atmosphere)");
  target.vector3("attitude_offset_deg", s.target_attitude_offset_rad, -180.0, 180.0, kDeg);
  readVehicle(target, s.target);
  target.finish();

  MapReader chaser = top.child("chaser");
  readVehicle(chaser, s.chaser);
  MapReader initial = chaser.child("initial_state");
  std::string frame = "target_port";
  initial.text("frame", frame);
  if (frame == "target_port")
    s.chaser_initial.frame = RelativeFrame::kTargetPort;
  else if (frame == "target_lvlh")
    s.chaser_initial.frame = RelativeFrame::kTargetLvlh;
  else
    initial.fail("chaser.initial_state.frame", "'" + frame + "'", "target_port or target_lvlh");
  initial.vector3("position_m", s.chaser_initial.position_m, -1e5, 1e5);
  initial.vector3("velocity_mps", s.chaser_initial.velocity_mps, -100.0, 100.0);
  initial.vector3("attitude_offset_deg", s.chaser_initial.attitude_offset_rad, -180.0, 180.0, kDeg);
  initial.vector3("angular_rate_offset_dps", s.chaser_initial.angular_rate_offset_radps, -10.0, 10.0, kDeg);
  initial.finish();
  MapReader actuator = chaser.child("actuator");
  actuator.vector3("max_force_n", s.chaser_actuator.max_force_n, 0.0, 1e5);
  actuator.vector3("max_torque_nm", s.chaser_actuator.max_torque_nm, 0.0, 1e5);
  actuator.number("min_impulse_bit_ns", s.chaser_actuator.min_impulse_bit_ns, 0.0, 1e3);
  actuator.number("min_angular_impulse_bit_nms", s.chaser_actuator.min_angular_impulse_bit_nms, 0.0, 1e3);
  actuator.number("force_noise_fraction", s.chaser_actuator.force_noise_fraction, 0.0, 1.0);
  actuator.number("torque_noise_fraction", s.chaser_actuator.torque_noise_fraction, 0.0, 1.0);
  actuator.finish();
  chaser.finish();

  MapReader env = top.child("environment");
  env.integer("gravity_degree", s.environment.gravity_degree, 0, 13);
  env.text("gravity_model_file", s.gravity_model_file);
  env.number("atmosphere_density_kgm3", s.environment.atmosphere_density_kgm3, 0.0, 1e-6);
  env.boolean("earth_rotation", s.environment.earth_rotation);
  env.angleDeg("greenwich_angle_at_epoch_deg", s.environment.greenwich_angle_at_epoch_rad, -360.0, 360.0);
  env.boolean("gravity_gradient_torque", s.environment.gravity_gradient_torque);
  env.finish();

  MapReader sim = top.child("simulation");
  sim.number("control_step_s", s.control_step_s, 0.0, 10.0, true);
  sim.number("integration_step_s", s.integration_step_s, 0.0, 10.0, true);
  sim.number("duration_s", s.duration_s, 0.0, 1e6, true);
  sim.finish();
  const double substeps = s.control_step_s / s.integration_step_s;
  if (std::abs(substeps - std::round(substeps)) > 1e-9 || std::round(substeps) < 1)
    sim.fail("simulation.integration_step_s", std::to_string(s.integration_step_s),
             "a whole fraction of simulation.control_step_s (" + std::to_string(s.control_step_s) + ")");

  MapReader contact = top.child("contact");
  CaptureEnvelope& envelope = s.contact.envelope;
  contact.boolean("enabled", s.contact.enabled);
  contact.number("min_closing_speed_mps", envelope.min_closing_speed_mps, 0.0, 10.0);
  contact.number("max_closing_speed_mps", envelope.max_closing_speed_mps, 0.0, 10.0);
  contact.number("max_lateral_misalignment_m", envelope.max_lateral_misalignment_m, 0.0, 10.0);
  contact.angleDeg("max_angular_misalignment_deg", envelope.max_angular_misalignment_rad, 0.0, 180.0);
  contact.number("max_lateral_rate_mps", envelope.max_lateral_rate_mps, 0.0, 10.0);
  contact.angleDeg("max_angular_rate_dps", envelope.max_angular_rate_radps, 0.0, 100.0);
  contact.number("time_tolerance_s", s.contact.time_tolerance_s, 1e-6, 1.0);
  contact.finish();
  if (envelope.min_closing_speed_mps > envelope.max_closing_speed_mps)
    contact.fail(
        "contact.min_closing_speed_mps", std::to_string(envelope.min_closing_speed_mps),
        "at most contact.max_closing_speed_mps (" + std::to_string(envelope.max_closing_speed_mps) + ")");

  const YAML::Node seeds = top.get("seeds");
  if (seeds.IsDefined() && !seeds.IsNull()) {
    if (!seeds.IsMap()) top.fail("seeds", describe(seeds), "a map of name: non-negative integer");
    for (const auto& item : seeds) {
      const std::string name = item.first.as<std::string>();
      try {
        s.seeds[name] = item.second.as<std::uint64_t>();
      } catch (const YAML::Exception&) {
        top.fail("seeds." + name, describe(item.second), "a non-negative integer");
      }
    }
  }
  // Sections read by the other nodes of a docking scenario; the dynamics leaves them to their owners.
  for (const char* section : {"lidar", "pose", "guidance", "faults", "run"}) top.get(section);
  top.finish();
  return s;
}

Scenario loadScenario(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ScenarioError("cannot read scenario file '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  Scenario s = parseScenario(text.str(), path);
  // A relative gravity model path is taken relative to the scenario file.
  if (!s.gravity_model_file.empty() && s.gravity_model_file.front() != '/') {
    const auto slash = path.find_last_of('/');
    if (slash != std::string::npos) s.gravity_model_file = path.substr(0, slash + 1) + s.gravity_model_file;
  }
  return s;
}

}  // namespace ardsim_dynamics
