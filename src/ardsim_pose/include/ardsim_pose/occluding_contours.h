// Sub-pixel placement of a target's occluding contours (where its surface ends against the background or
// against structure far behind), for the directions that point-to-plane ICP leaves weak: a plane seen
// face-on (Hubble's aft bulkhead) says nothing about sliding across it, and offsets to the nearest model
// points place its rim only to the sampling (they carry no information within half a pixel's footprint).
// Here each pair of neighbouring pixels across a depth edge of the scan (a return, and beside it none or one
// much farther) says the contour crosses between their centres; the model's contour along that line at a
// pose is where the model's triangles there, near the return's depth, stop covering the line through the
// pixel centres (the rays the sensor samples). The midpoint is off by at most half a pixel, evenly either
// way, so hundreds of pairs place the contour far better than a pixel. ROS-free.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ardsim_lidar/sensor.h"
#include "ardsim_pose/pose_types.h"
#include "ardsim_pose/reference_model.h"

namespace ardsim_pose {

class OccludingContours {
 public:
  // max_pairs: at most this many pairs a frame, evenly spread over them (0: all); depth_jump_m: a neighbour
  // at least this much farther (or with no return) is across an edge; window_px: how far along the pair's
  // line the model's contour is looked for (beyond it the pair is not used).
  explicit OccludingContours(const ardsim_lidar::Intrinsics& intrinsics, int max_pairs = 0,
                             double depth_jump_m = 0.3, int window_px = 3);

  // The edge pairs of a frame whose returns are among pixels (indices into cloud.points).
  void extract(const OrganizedCloud& cloud, const std::vector<int>& pixels);
  std::size_t pairs() const { return pairs_.size(); }

  // The triangles of the visible rigid patches (of patches) with samples that project near a pair's line at
  // T_lidar_target; the accumulation follows them while the pose moves less than a pixel or two from
  // T_lidar_target.
  void selectCandidates(const ReferenceModel& model, const std::vector<std::uint32_t>& patches,
                        const Eigen::Isometry3d& T_lidar_target);

  // Adds to the normal equations (H, g) of a twist (v, w) about centre, p' = p + w x (p - centre) + v, one
  // row per pair whose model contour lies within the window: the pair's midpoint minus the model's contour
  // along the pair's line, in metres at the contour's depth, weighted (sigma_m / the contour's sigma)^2 with
  // sigma_px the contour's own in pixels, Tukey-weighted within limit_px. The rows measure the translation,
  // and with with_boresight_rotation the rotation about lidar z, never the tilt across it. Returns the rows
  // added.
  int accumulate(bool with_boresight_rotation, const Eigen::Isometry3d& T_lidar_target,
                 const Eigen::Vector3d& centre, double sigma_m, double sigma_px, double limit_px,
                 Eigen::Matrix<double, 6, 6>* H, Eigen::Matrix<double, 6, 1>* g);

  // A prediction of the lateral translation (from the pose, lidar x, y, m; its covariance, m^2) that the
  // vote weighs against the strips' counts: a translation d scores its votes less weight / 2 times
  // (d - translation)^T (covariance + cell^2)^-1 (d - translation). Only in the frame's first
  // kMaxVotesWithPrior votes: where the members' strips move apart between two poses (and so vote again), a
  // pull at every vote swung the pose between two plateaus (an approach dataset's frame to the iteration
  // limit).
  struct VotePrior {
    Eigen::Vector2d translation_m = Eigen::Vector2d::Zero();
    Eigen::Matrix2d covariance_m2 = Eigen::Matrix2d::Identity();
    double weight = 0.0;
  };
  // The lateral translation (lidar x, y) alone, as the set of translations that put the model's contour of
  // every pair between its two pixel centres: the midpoints above share a sub-pixel phase along a straight
  // edge, and their mean is off by up to half a pixel with the target's position across the pixels (Hubble's
  // bulkhead rim at 45 m: lateral error periodic in the image position, swinging 7 mm). The pairs vote over
  // translations within reach_px (a strip each) at the frame's first call and when vote_again; the strips
  // holding the winner (a bad pair, a dropout beside the edge, is outvoted) are its members until the next
  // vote, intersected exactly at each call; the polygon's centroid is added to (H, g) as a measurement of
  // (v_x, v_y), with its covariance (of a uniform distribution over it) widened by floor_px, in the units of
  // sigma_m, and no less information than min_information in any direction; with prior, the vote weighs it
  // (VotePrior above). Returns the members intersected (0: nothing added).
  int accumulateConsensus(const Eigen::Isometry3d& T_lidar_target, double sigma_m, double reach_px,
                          double floor_px, double min_information, bool vote_again,
                          Eigen::Matrix<double, 6, 6>* H, Eigen::Matrix<double, 6, 1>* g,
                          const VotePrior* prior = nullptr);
  // Of the last accumulateConsensus that added something: the lateral translation (lidar x, y, m) from its
  // pose to the polygon's centroid and its covariance (m^2, the floor's included, before min_information).
  const Eigen::Vector2d& consensusMean() const { return consensus_mean_m_; }
  const Eigen::Matrix2d& consensusCovariance() const { return consensus_covariance_m2_; }

 private:
  struct Pair {
    int u = 0, v = 0;    // the return's pixel
    int du = 0, dv = 0;  // towards its neighbour across the edge
    float depth_m = 0.0f;
    int run = 1;  // pairs of this direction side by side along the edge, this one among them
  };
  struct Found {
    bool ok = false;
    double offset_px = 0.0;  // the model's contour minus the pair's midpoint, along (du, dv)
    // The contour point: image coordinates (px) and depth (m).
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    // The contour's slope there: its image coordinate along the pair's axis per px along the line.
    double slope = 0.0;
  };
  // A candidate triangle projected at a pose: its corners (image px, depth m) and image bounds.
  struct Projected {
    std::array<Eigen::Vector3f, 3> corners;
    float u_min, u_max, v_min, v_max;
  };
  // Where a triangle covers the pair's line: from along0 to along1 (px from the return's centre towards its
  // neighbour), with the depth at along1.
  struct Cover {
    float along0, along1, depth1;
    float slope1;  // of the triangle's edge at along1, px along the pair's axis per px along its line
  };
  // Projects the candidates at T and lists them by the pixel columns and rows of the pairs' lines they cross.
  void project(const Eigen::Isometry3d& T_lidar_target);
  Found find(const Pair& pair);

  ardsim_lidar::Intrinsics intrinsics_;
  float depth_jump_m_;
  int window_px_;
  int max_pairs_;
  std::vector<Pair> pairs_;
  std::vector<Pair> kept_;                    // scratch: the pairs kept of max_pairs_
  std::vector<float> depth_;                  // scratch: per pixel, +inf where no return
  std::vector<std::uint8_t> near_saturated_;  // scratch: per pixel, within the bloom of a saturated return
  std::vector<std::uint8_t> pair_at_;         // scratch: per pixel and direction, a pair there
  std::vector<std::uint8_t> near_pair_;       // scratch: per pixel, near a pair's line
  // Pairs across rows (dv): their columns; across columns (du): their rows.
  std::vector<std::uint8_t> column_has_pair_, row_has_pair_;
  std::vector<ReferenceModel::Triangle> candidates_;  // target frame
  std::vector<std::uint32_t> candidate_mark_;         // per model triangle: the selection that took it
  std::uint32_t selection_ = 0;
  std::vector<Projected> projected_;
  std::vector<std::vector<std::uint32_t>> by_column_, by_row_;  // indices into projected_
  std::vector<Cover> covers_;                                   // scratch of find
  // A pair in accumulateConsensus: its model contour's offset at a lateral translation d (m) from the pose
  // is offset_px + a . d.
  struct Strip {
    Eigen::Vector2d a;  // px/m
    double offset_px;
    std::size_t pair;  // its index in pairs_
    bool member = false;
  };
  // The translation within reach_m of the pose that the most strips_ hold (weighed against prior, if any).
  Eigen::Vector2d vote(double reach_m, const VotePrior* prior);
  static constexpr int kMaxVotesWithPrior = 4;
  int votes_this_frame_ = 0;
  // polygon_: the intersection of the member strips within reach_m; returns their number.
  int intersectMembers(double reach_m);
  // The mean and covariance of a uniform distribution over polygon_ (false: no area).
  bool polygonMoments(Eigen::Vector2d* mean, Eigen::Matrix2d* covariance) const;
  std::vector<Strip> strips_;                       // scratch of accumulateConsensus
  std::vector<std::uint8_t> members_;               // per pair, in the frame's consensus (empty: none yet)
  std::vector<int> votes_;                          // scratch: its vote, a difference array by rows
  std::vector<Eigen::Vector2d> polygon_, clipped_;  // scratch: its intersection
  Eigen::Vector2d consensus_mean_m_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d consensus_covariance_m2_ = Eigen::Matrix2d::Identity();
};

}  // namespace ardsim_pose
