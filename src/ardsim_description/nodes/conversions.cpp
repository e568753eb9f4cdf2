#include "conversions.h"

#include <algorithm>

#include <tf2_eigen/tf2_eigen.h>

namespace ardsim_description {

geometry_msgs::TransformStamped toTransformStamped(const Eigen::Isometry3d& T_parent_child,
                                                   const std::string& parent, const std::string& child,
                                                   const ros::Time& stamp) {
  geometry_msgs::TransformStamped msg = tf2::eigenToTransform(Eigen::Affine3d(T_parent_child.matrix()));
  msg.header.stamp = stamp;
  msg.header.frame_id = parent;
  msg.child_frame_id = child;
  return msg;
}

Eigen::Isometry3d toIsometry(const geometry_msgs::Transform& transform) {
  return tf2::transformToEigen(transform);
}

visualization_msgs::Marker toMarker(const TriangleMesh& mesh, const std::string& frame_id,
                                    const std::string& ns, float alpha) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.ns = ns;
  marker.id = 0;
  marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
  marker.color.a = alpha;
  marker.points.reserve(3 * mesh.triangles.size());
  marker.colors.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Material& material = mesh.materials[mesh.triangle_material[t]];
    std_msgs::ColorRGBA colour;
    // Lifted so that dark materials (solar cells) stay visible in rviz.
    const float grey = 0.25f + 0.75f * std::clamp(material.reflectivity, 0.0f, 1.0f);
    colour.r = material.retro_reflector ? 1.0f : grey;
    colour.g = material.retro_reflector ? 0.0f : grey;
    colour.b = material.retro_reflector ? 0.0f : grey;
    colour.a = alpha;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& v = mesh.vertices[mesh.triangles[t][k]];
      geometry_msgs::Point p;
      p.x = v.x();
      p.y = v.y();
      p.z = v.z();
      marker.points.push_back(p);
      marker.colors.push_back(colour);
    }
  }
  return marker;
}

}  // namespace ardsim_description
