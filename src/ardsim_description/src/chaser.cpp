// The chaser: a Crew-Dragon-sized capsule and trunk with an IDSS port on its nose (frames.h: x towards the
// port, origin at the centre of mass). Tags as in iss.cpp.
#include <cmath>

#include "ardsim_description/models.h"
#include "model_builder.h"

namespace ardsim_description {

VehicleModel buildChaserModel() {
  ModelBuilder b;
  const auto skin = b.material("chaser_skin", 0.7f);  // [estimate]
  constexpr int kSegments = 48;

  // 8.1 m with trunk, 4.0 m diameter, capsule 4.5 m with a 15 deg sidewall [src]: the capsule rises from the
  // heat shield at x = -1.5 to the port adapter at x = 2.7 (radius 2.0 - 4.2 tan 15 deg = 0.87 m [derived]),
  // the port plane at x = 3.0 (frames.h), the trunk below down to x = -5.1.
  const double tan15 = std::tan(15.0 * M_PI / 180.0);
  b.frustum(Eigen::Isometry3d::Identity(), 2.0, 2.0 - 4.2 * tan15, -1.5, 2.7, kSegments,
            {skin, b.part("capsule", false)}, Collide::kYes);
  b.frustum(Eigen::Isometry3d::Identity(), 1.85, 1.85, -5.1, -1.5, kSegments, {skin, b.part("trunk", false)},
            Collide::kYes);

  IdssInterface port;
  port.tunnel_outer_radius_m = 0.7;  // [estimate]
  port.hatch_depth_m = 0.3;          // at the top of the capsule
  port.reflectors = false;
  addIdssInterface(b, T_chaser_port(), port);

  return b.finish(chaserMassProperties());
}

TriangleMesh buildChaser() {
  return buildChaserModel().mesh;
}

VehicleModel buildTargetModel(TargetKind kind) {
  return kind == TargetKind::kIss ? buildIssModel() : buildHubbleModel();
}

TriangleMesh buildTarget(TargetKind kind, const IssOptions& iss, const HubbleOptions& hubble) {
  return kind == TargetKind::kIss ? buildIss(iss) : buildHubble(hubble);
}

}  // namespace ardsim_description
