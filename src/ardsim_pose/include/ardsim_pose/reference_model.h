// The ICP's a-priori model: the target's rigid structure (articulated parts such as solar arrays and
// radiators left out, they turn) sampled to points with their triangle's normal, a KD-tree over all of them
// built once, and the per-frame visibility prediction that crops it to what the sensor can see from a pose.
// ROS-free.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "ardsim_description/mesh.h"
#include "ardsim_lidar/sensor.h"

namespace ardsim_pose {

// Squared distance summed x, y, z in that order, as nanoflann's L2_Simple_Adaptor sums it: every search that
// stands in for the tree (the balls, the visible-point grid) finds the same nearest point and distance.
inline float treeDistanceSq(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  float sum = 0.0f;
  for (int d = 0; d < 3; ++d) {
    const float diff = a[d] - b[d];
    sum += diff * diff;
  }
  return sum;
}

struct ReferenceModelOptions {
  // Sample spacing on the surfaces grows with the distance from the docking port: the port is seen from
  // metres, the far structure only from tens of metres, where a pixel is as wide as the coarser spacing.
  double spacing_at_port_m = 0.03;
  double spacing_growth_per_m = 0.004;  // spacing added per metre of distance from the port
  double max_spacing_m = 0.25;
  double patch_spacings =
      4.0;  // visibility is decided per patch: samples of one triangle within this many spacings
  double chunk_size_m = 3.0;  // patches are culled against the view frustum in cubes of this size
};

// Throws std::invalid_argument naming the option, its value and the allowed range.
void validate(const ReferenceModelOptions& options);

class ReferenceModel {
 public:
  // mesh: the rigid structure in the target body frame; T_target_port: where the spacing is finest.
  ReferenceModel(const ardsim_description::TriangleMesh& mesh, const Eigen::Isometry3d& T_target_port,
                 const ReferenceModelOptions& options = {});
  ~ReferenceModel();
  ReferenceModel(const ReferenceModel&) = delete;
  // This model with its articulated parts (patchArticulated) turned by angle_rad about the axis (unit)
  // through origin, target frame: a part that turns moved without sampling the mesh anew (Hubble: 1-4 ms,
  // instead of 70-270). The samples and their grouping into patches and chunks stay; the turned patches' and
  // their chunks' bounds are made anew. No KD-tree is built: a model with parts that turn has one over its
  // rigid points and one over the articulated ones where they were sampled (queries turned there), shared
  // by every model turned from it (one tree over all of Hubble's ~230k points cost each turn ~40 ms).
  std::shared_ptr<const ReferenceModel> withArticulatedTurned(const Eigen::Vector3d& origin,
                                                              const Eigen::Vector3d& axis,
                                                              double angle_rad) const;
  ReferenceModel& operator=(const ReferenceModel&) = delete;

  std::size_t size() const { return arrays_.points.size(); }
  const std::vector<Eigen::Vector3f>& points() const { return arrays_.points; }    // target frame, m
  const std::vector<Eigen::Vector3f>& normals() const { return arrays_.normals; }  // unit, outward
  const std::vector<float>& spacing() const { return arrays_.spacing; }            // m, per point
  // The points' x, y and z coordinates as three arrays (vectorized transforms of ranges of points).
  const Eigen::ArrayXf& coordinates(int axis) const { return arrays_.coordinates[axis]; }

  // Nearest point with visible[index] != 0 within sqrt(max_distance_sq) of query (target frame); -1 if none.
  int nearestVisible(const Eigen::Vector3f& query, float max_distance_sq,
                     const std::vector<std::uint8_t>& visible, float* distance_sq) const;
  // nearestVisible that also appends to near every visible point within margin_m of the nearest one's
  // distance (every visible point within the gate when there is none) and sets radius_m to the radius of the
  // ball around query that near then covers: a later query q' with a nearest candidate in near closer than
  // radius_m - |q' - query| has found its nearest visible point.
  int nearestVisibleWithNeighbours(const Eigen::Vector3f& query, float max_distance_sq,
                                   const std::vector<std::uint8_t>& visible, float margin_m,
                                   float* distance_sq, float* radius_m,
                                   std::vector<std::uint32_t>* near) const;
  // Squared distance from query to point index, computed as the tree computes it.
  float distanceSq(const Eigen::Vector3f& query, std::uint32_t index) const {
    return treeDistanceSq(query, arrays_.points[index]);
  }
  // Whether any model point, visible or not, lies within sqrt(max_distance_sq) of query (target frame).
  bool anyWithin(const Eigen::Vector3f& query, float max_distance_sq) const;

  // Samples of one triangle close together: one visibility decision for all (points [begin, end)).
  struct Patch {  // its centre, normal and bounding radius: patchCentres, patchNormals, patchRadii
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
  };
  // Patches close together: one frustum test for all (patches [begin, end), plane runs [run_begin, run_end)).
  struct Chunk {
    Eigen::Vector3f centre;
    float radius = 0.0f;
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
    std::uint32_t run_begin = 0;
    std::uint32_t run_end = 0;
  };
  // A chunk's patches of one triangle (patches [begin, end)): one back-face test for all where the sensor is
  // clearly on one side of the plane (normal . centre of each patch between offset_min and offset_max;
  // extent: the largest |centre|_1, for how far a patch's own test may round).
  struct PlaneRun {
    Eigen::Vector3f normal;
    float offset_min = 0.0f;
    float offset_max = 0.0f;
    float extent = 0.0f;
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
  };
  const std::vector<Patch>& patches() const { return arrays_.patches; }
  // Whether a patch is of a part that turns (ardsim_description::Part::articulated: Hubble's arrays, in the
  // model at the angle the scans measure): where it ends is only as good as that angle.
  bool patchArticulated(std::uint32_t patch) const { return arrays_.patch_articulated[patch] != 0; }
  bool hasArticulatedParts() const { return split_ != nullptr; }
  // Whether a point is of a part that turns (its patch's flag, per point).
  bool pointArticulated(std::uint32_t point) const { return arrays_.point_articulated[point] != 0; }
  // The mesh triangle whose samples a patch holds (vertices, target frame; turned with its part): where the
  // surface really ends, which its samples give only to a spacing.
  using Triangle = std::array<Eigen::Vector3f, 3>;
  std::uint32_t patchTriangle(std::uint32_t patch) const { return arrays_.patch_triangle[patch]; }
  const Triangle& triangle(std::uint32_t index) const { return arrays_.triangles[index]; }
  std::size_t triangleCount() const { return arrays_.triangles.size(); }
  // The patches' centres, normals (axis 0-2) and radii as arrays (vectorized per chunk).
  const Eigen::ArrayXf& patchCentres(int axis) const { return arrays_.patch_centres[axis]; }
  const Eigen::ArrayXf& patchNormals(int axis) const { return arrays_.patch_normals[axis]; }
  const Eigen::ArrayXf& patchRadii() const { return arrays_.patch_radii; }
  const std::vector<Chunk>& chunks() const { return arrays_.chunks; }
  const std::vector<PlaneRun>& planeRuns() const { return arrays_.plane_runs; }

 private:
  struct KdTree;
  struct SplitTrees;
  ReferenceModel() = default;  // withArticulatedTurned's copy
  // nanoflann searches of every point (tree_), or of the rigid ones and the turned ones (split_).
  template <class Result>
  void searchRigid(Result& result, const Eigen::Vector3f& query) const;
  template <class Result>
  void searchTurned(Result& result, const Eigen::Vector3f& query) const;
  // The model's arrays: what a turn copies, and the memory a turned model gone leaves for the next turn.
  struct Arrays {
    std::vector<Eigen::Vector3f> points;
    std::vector<Eigen::Vector3f> normals;
    std::vector<float> spacing;
    std::array<Eigen::ArrayXf, 3> coordinates;
    std::array<Eigen::ArrayXf, 3> patch_centres;
    std::array<Eigen::ArrayXf, 3> patch_normals;
    Eigen::ArrayXf patch_radii;
    std::vector<Patch> patches;
    std::vector<std::uint8_t> patch_articulated;  // beside patches: their loops read begin and end only
    std::vector<std::uint8_t> point_articulated;
    std::vector<std::uint32_t> patch_triangle;  // index into triangles
    std::vector<Triangle> triangles;            // the mesh's
    std::vector<Chunk> chunks;
    std::vector<PlaneRun> plane_runs;
  };
  // The plane run's bounds from its patches' centres and normal.
  void boundPlaneRun(PlaneRun* run) const;
  Arrays arrays_;
  // One tree over every point, or with parts that turn split_, shared by the models turned from one another.
  std::unique_ptr<KdTree> tree_;
  std::shared_ptr<const SplitTrees> split_;
  Eigen::Isometry3d T_model_sampled_ = Eigen::Isometry3d::Identity();  // articulated parts: as sampled -> now
  Eigen::Isometry3f T_sampled_model_ = Eigen::Isometry3f::Identity();  // its inverse, for the queries
};

// Model points [first, second).
using PointRange = std::pair<std::uint32_t, std::uint32_t>;

struct VisibilityOptions {
  int cell_px = 4;          // the depth buffer's cells are cell_px x cell_px sensor pixels
  double margin_px = 12.0;  // points this far outside the image still count (the prediction is not exact)
  double depth_tolerance_m =
      0.2;  // a point within this (or 3 cells' width) behind the nearest surface is seen
  // The lidar returns nothing from a surface it sees more obliquely than this (its noise model's
  // max_incidence_deg; must match it): such patches still hide what is behind them, but are left out of the
  // visible points, which no scan point can lie on (90: back faces only).
  double max_incidence_deg = 80.0;
};
void validate(const VisibilityOptions& options);

// What the sensor can see of the model from a pose: front-facing patches inside the field of view (plus
// margin) and not hidden by nearer structure, by a coarse depth buffer of splatted patches.
class VisibilityPredictor {
 public:
  VisibilityPredictor(const ardsim_lidar::Intrinsics& intrinsics, const VisibilityOptions& options);

  // The per-cell depth of the nearest predicted surface and, with_points, which model points are visible
  // (visible()). Returns the number of visible points; without points the depths alone (no visibility test
  // per patch), 0.
  // oblique: patches seen more obliquely than max_incidence_deg count as visible too (a pose that is only
  // roughly known, whose incidences are not).
  int predict(const ReferenceModel& model, const Eigen::Isometry3d& T_lidar_target, bool with_points = true,
              bool oblique = false);
  // One flag per point of the model of the last predict(); all 0 after one without points.
  const std::vector<std::uint8_t>& visible() const { return visible_; }

  int gridWidth() const { return grid_width_; }
  int gridHeight() const { return grid_height_; }
  int cellPx() const { return options_.cell_px; }
  // Nearest predicted model depth (lidar z, m) per cell from the last predict(); +inf where no model surface.
  const std::vector<float>& modelDepth() const { return model_depth_; }
  // Depth (lidar z, m) of the nearest predicted model surface, margin included; +inf where none.
  float nearestDepth() const { return nearest_depth_; }
  // Cell of a pixel (inside the image).
  int cellOfPixel(int u, int v) const { return (v / options_.cell_px) * grid_width_ + u / options_.cell_px; }
  // The patches judged visible by the last predict() (their points are the visible ones), in order.
  const std::vector<std::uint32_t>& visiblePatches() const { return visible_patches_; }
  // Their points as ranges of model indices, consecutive patches joined.
  const std::vector<PointRange>& visibleRanges() const { return visible_ranges_; }

 private:
  ardsim_lidar::Intrinsics intrinsics_;
  VisibilityOptions options_;
  int grid_width_ = 0;
  int grid_height_ = 0;
  int margin_cells_ = 0;
  float cos_max_incidence_sq_ = 0.0f;  // squared cosine of max_incidence_deg; 0: no grazing test
  int padded_width_ = 0;
  int padded_height_ = 0;
  std::vector<float> depth_;        // padded grid
  std::vector<float> model_depth_;  // image grid
  float nearest_depth_ = 0.0f;
  struct Candidate {
    std::uint32_t patch;
    std::int32_t cell;  // padded grid
    float depth;
  };
  // Scratch: a prediction's front patches splatted, with their nearest depth (written by index, sized for
  // every patch once: no capacity check per patch).
  std::vector<Candidate> candidates_;
  std::vector<std::uint32_t> visible_patches_;
  std::vector<std::uint8_t> visible_;
  std::vector<PointRange> visible_ranges_;      // the flags set to 1
  Eigen::ArrayXf depth_z_, u_, v_, radius_px_;  // scratch: per patch of a chunk
};

// The visible model points binned by the pixels they project to at one pose: an exact nearest-visible-point
// search that reads a few bins around the query's own instead of descending the KD-tree over every model
// point (three in four of those near a query are hidden). A point outside the window of bins around the
// query lies at least a known angle off the query's ray, so at least a known distance away: when the nearest
// point found in the window is closer than that, it is the nearest of all; otherwise the search says it
// cannot answer and the caller asks the tree.
class VisiblePointGrid {
 public:
  VisiblePointGrid(const ardsim_lidar::Intrinsics& intrinsics, double margin_px);

  // Bins the model points in the ranges (target frame) as seen from T_lidar_target.
  // depth_m: the depth of the nearest predicted surface (the bins' size follows it).
  void build(const ReferenceModel& model, const std::vector<PointRange>& ranges,
             const Eigen::Isometry3d& T_lidar_target, double depth_m);
  // The nearest binned point within sqrt(max_distance_sq) of query (target frame; index -1: none) when the
  // grid can tell exactly (returns true; false: ask the tree). With near: as
  // ReferenceModel::nearestVisibleWithNeighbours, the ball's radius and the points within it besides.
  bool nearest(const Eigen::Vector3f& query, float max_distance_sq, int* index, float* distance_sq,
               float margin_m = 0.0f, float* radius_m = nullptr,
               std::vector<std::uint32_t>* near = nullptr) const;

 private:
  ardsim_lidar::Intrinsics intrinsics_;
  int pad_px_ = 0;
  int bin_px_ = 1;
  int bins_wide_ = 0;
  int bins_high_ = 0;
  float min_cos_sq_ = 1.0f;  // squared cosine of the off-axis angle of the padded image's corner
  Eigen::Matrix3f R_ = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t_ = Eigen::Vector3f::Zero();
  std::vector<std::uint32_t> bin_begin_;      // (bins_wide_ + 2) x (bins_high_ + 2) + 2: a border of one bin
  std::vector<float> bin_x_, bin_y_, bin_z_;  // target frame, bin by bin (by axis: read four at a time)
  std::vector<std::uint32_t> bin_index_;      // their model point indices
  std::vector<std::int32_t> bin_of_;          // scratch: bin per point of the ranges
  mutable std::vector<std::pair<float, std::uint32_t>> found_;  // scratch of nearest()
};

}  // namespace ardsim_pose
