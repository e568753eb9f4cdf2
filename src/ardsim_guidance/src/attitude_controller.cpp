#include "ardsim_guidance/attitude_controller.h"

#include "ardsim_guidance/geometry.h"

namespace ardsim_guidance {

Eigen::Vector3d attitudeTorque(const AttitudeOptions& o, const Eigen::Quaterniond& q_inertial_body,
                               const Eigen::Vector3d& rate, const Eigen::Quaterniond& q_inertial_desired,
                               const Eigen::Vector3d& desired_rate) {
  const double w = o.bandwidth_rad_s;
  const double kp = w * w, kd = 2.0 * o.damping_ratio * w;
  const Eigen::Vector3d error = attitudeError(q_inertial_body, q_inertial_desired);
  const Eigen::Vector3d j_rate = o.inertia_kg_m2.cwiseProduct(rate);
  return o.inertia_kg_m2.cwiseProduct(-kp * error - kd * (rate - desired_rate)) + rate.cross(j_rate);
}

}  // namespace ardsim_guidance
