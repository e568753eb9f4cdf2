#include "ardsim_pose/reference_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include <nanoflann.hpp>

namespace ardsim_pose {

namespace {

void require(bool ok, const std::string& name, double value, const std::string& allowed) {
  if (!ok) throw std::invalid_argument(name + " = " + std::to_string(value) + " is out of range: " + allowed);
}

// Points of a triangle from the R2 low-discrepancy sequence folded into the triangle: even coverage without a
// random generator, the same model on every run.
void sampleTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, int count,
                    std::vector<Eigen::Vector3f>* out) {
  constexpr double kG = 1.32471795724474602596;  // plastic number
  constexpr double kA1 = 1.0 / kG;
  constexpr double kA2 = 1.0 / (kG * kG);
  for (int i = 0; i < count; ++i) {
    double s = std::fmod(0.5 + kA1 * (i + 1), 1.0);
    double t = std::fmod(0.5 + kA2 * (i + 1), 1.0);
    if (s + t > 1.0) {
      s = 1.0 - s;
      t = 1.0 - t;
    }
    out->push_back(a + static_cast<float>(s) * (b - a) + static_cast<float>(t) * (c - a));
  }
}

}  // namespace

void validate(const ReferenceModelOptions& o) {
  require(std::isfinite(o.spacing_at_port_m) && o.spacing_at_port_m >= 0.005 && o.spacing_at_port_m <= 1.0,
          "model/spacing_at_port_m", o.spacing_at_port_m, "0.005 .. 1");
  require(
      std::isfinite(o.spacing_growth_per_m) && o.spacing_growth_per_m >= 0.0 && o.spacing_growth_per_m <= 0.1,
      "model/spacing_growth_per_m", o.spacing_growth_per_m, "0 .. 0.1");
  require(std::isfinite(o.max_spacing_m) && o.max_spacing_m >= o.spacing_at_port_m && o.max_spacing_m <= 2.0,
          "model/max_spacing_m", o.max_spacing_m, "spacing_at_port_m .. 2");
  require(std::isfinite(o.patch_spacings) && o.patch_spacings >= 1.0 && o.patch_spacings <= 20.0,
          "model/patch_spacings", o.patch_spacings, "1 .. 20");
  require(std::isfinite(o.chunk_size_m) && o.chunk_size_m >= 0.5 && o.chunk_size_m <= 50.0,
          "model/chunk_size_m", o.chunk_size_m, "0.5 .. 50");
}

void validate(const VisibilityOptions& o) {
  require(o.cell_px >= 1 && o.cell_px <= 32, "visibility/cell_px", o.cell_px, "1 .. 32");
  require(std::isfinite(o.margin_px) && o.margin_px >= 0.0 && o.margin_px <= 256.0, "visibility/margin_px",
          o.margin_px, "0 .. 256");
  require(std::isfinite(o.depth_tolerance_m) && o.depth_tolerance_m > 0.0 && o.depth_tolerance_m <= 10.0,
          "visibility/depth_tolerance_m", o.depth_tolerance_m, "> 0 .. 10");
}

// nanoflann adaptor over the model points.
struct ReferenceModel::KdTree {
  struct Adaptor {
    const std::vector<Eigen::Vector3f>* points;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(std::size_t index, std::size_t dim) const { return (*points)[index][dim]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Adaptor>, Adaptor, 3,
                                                    std::uint32_t>;
  Adaptor adaptor;
  Index index;
  explicit KdTree(const std::vector<Eigen::Vector3f>* points)
      : adaptor{points}, index(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    index.buildIndex();
  }
};

namespace {

// nanoflann result set keeping the nearest point that the visibility mask lets through: the model is cropped
// by index, the tree is never rebuilt.
struct NearestVisibleResult {
  const std::uint8_t* visible;
  float best_distance_sq;
  std::int64_t best_index = -1;
  bool addPoint(float distance_sq, std::uint32_t index) {
    if (visible[index] && distance_sq < best_distance_sq) {
      best_distance_sq = distance_sq;
      best_index = index;
    }
    return true;
  }
  float worstDist() const { return best_distance_sq; }
  bool full() const { return best_index >= 0; }
};

// The nearest visible point, collecting on the way every visible point within margin of it: the search
// reach is the nearest distance found so far plus the margin (the gate until one is found).
struct NeighbourhoodResult {
  const std::uint8_t* visible;
  float max_distance_sq;
  float margin;
  std::vector<std::pair<float, std::uint32_t>>* found;
  float reach_sq = max_distance_sq;
  float best_distance_sq = max_distance_sq;
  std::int64_t best_index = -1;
  bool addPoint(float distance_sq, std::uint32_t index) {
    if (!visible[index] || !(distance_sq < reach_sq)) return true;
    found->push_back({distance_sq, index});
    if (distance_sq < best_distance_sq) {
      best_distance_sq = distance_sq;
      best_index = index;
      const float reach = std::sqrt(distance_sq) + margin;
      reach_sq = std::min(max_distance_sq, reach * reach);
    }
    return true;
  }
  float worstDist() const { return reach_sq; }
  bool full() const { return best_index >= 0; }
};

}  // namespace

ReferenceModel::ReferenceModel(const ardsim_description::TriangleMesh& mesh,
                               const Eigen::Isometry3d& T_target_port, const ReferenceModelOptions& options) {
  validate(options);
  const Eigen::Vector3f port = T_target_port.translation().cast<float>();
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
  std::vector<float> spacing;
  std::vector<std::uint32_t> triangle_of;
  std::vector<Eigen::Vector3f> samples;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& triangle = mesh.triangles[t];
    const Eigen::Vector3f& a = mesh.vertices[triangle[0]];
    const Eigen::Vector3f& b = mesh.vertices[triangle[1]];
    const Eigen::Vector3f& c = mesh.vertices[triangle[2]];
    const Eigen::Vector3f cross = (b - a).cross(c - a);
    const float area = 0.5f * cross.norm();
    if (!(area > 1e-10f)) continue;
    const Eigen::Vector3f normal = cross.normalized();
    const Eigen::Vector3f centroid = (a + b + c) / 3.0f;
    const double s =
        std::min(options.max_spacing_m,
                 options.spacing_at_port_m + options.spacing_growth_per_m * (centroid - port).norm());
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    // Enough points for the area, and for the length of long thin triangles (truss members).
    const int count = std::max(1, static_cast<int>(std::ceil(std::max(area / (s * s), longest / s))));
    samples.clear();
    sampleTriangle(a, b, c, count, &samples);
    for (const Eigen::Vector3f& p : samples) {
      points.push_back(p);
      normals.push_back(normal);
      spacing.push_back(static_cast<float>(s));
      triangle_of.push_back(t);
    }
  }
  if (points.empty()) throw std::invalid_argument("reference model: the mesh has no triangles with area");

  // Group the samples into patches (one triangle, a cube of patch_spacings spacings), the patches into
  // chunks, and store the points patch by patch, the patches chunk by chunk.
  std::map<std::tuple<std::uint32_t, int, int, int>, std::vector<std::uint32_t>> patch_members;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    const float size = static_cast<float>(options.patch_spacings) * spacing[i];
    const Eigen::Vector3f& p = points[i];
    patch_members[{triangle_of[i], static_cast<int>(std::floor(p.x() / size)),
                   static_cast<int>(std::floor(p.y() / size)), static_cast<int>(std::floor(p.z() / size))}]
        .push_back(i);
  }
  std::map<std::tuple<int, int, int>, std::vector<const std::vector<std::uint32_t>*>> chunk_members;
  const float inv = static_cast<float>(1.0 / options.chunk_size_m);
  for (const auto& patch : patch_members) {
    const Eigen::Vector3f& p = points[patch.second.front()];
    chunk_members[{static_cast<int>(std::floor(p.x() * inv)), static_cast<int>(std::floor(p.y() * inv)),
                   static_cast<int>(std::floor(p.z() * inv))}]
        .push_back(&patch.second);
  }
  points_.reserve(points.size());
  normals_.reserve(points.size());
  spacing_.reserve(points.size());
  for (const auto& chunk_entry : chunk_members) {
    Chunk chunk;
    chunk.begin = static_cast<std::uint32_t>(patches_.size());
    Eigen::AlignedBox3f chunk_box;
    for (const std::vector<std::uint32_t>* members : chunk_entry.second) {
      Patch patch;
      patch.begin = static_cast<std::uint32_t>(points_.size());
      patch.normal = normals[members->front()];
      Eigen::AlignedBox3f box;
      for (std::uint32_t i : *members) {
        points_.push_back(points[i]);
        normals_.push_back(normals[i]);
        spacing_.push_back(spacing[i]);
        box.extend(points[i]);
      }
      patch.end = static_cast<std::uint32_t>(points_.size());
      patch.centre = box.center();
      // Half a spacing beyond the outermost samples: the surface the samples stand for.
      patch.radius = 0.5f * box.diagonal().norm() + 0.5f * spacing[members->front()];
      patches_.push_back(patch);
      chunk_box.extend(box);
    }
    chunk.end = static_cast<std::uint32_t>(patches_.size());
    chunk.centre = chunk_box.center();
    chunk.radius = 0.5f * chunk_box.diagonal().norm();
    chunks_.push_back(chunk);
  }
  tree_ = std::make_unique<KdTree>(&points_);
}

ReferenceModel::~ReferenceModel() = default;

int ReferenceModel::nearestVisible(const Eigen::Vector3f& query, float max_distance_sq,
                                   const std::vector<std::uint8_t>& visible, float* distance_sq) const {
  NearestVisibleResult result{visible.data(), max_distance_sq};
  tree_->index.findNeighbors(result, query.data(), nanoflann::SearchParams());
  *distance_sq = result.best_distance_sq;
  return static_cast<int>(result.best_index);
}

int ReferenceModel::nearestVisibleWithNeighbours(const Eigen::Vector3f& query, float max_distance_sq,
                                                 const std::vector<std::uint8_t>& visible, float margin_m,
                                                 float* distance_sq, float* radius_m,
                                                 std::vector<std::uint32_t>* near) const {
  thread_local std::vector<std::pair<float, std::uint32_t>> found;
  found.clear();
  NeighbourhoodResult result{visible.data(), max_distance_sq, margin_m, &found};
  tree_->index.findNeighbors(result, query.data(), nanoflann::SearchParams());
  // Points collected while the reach was still wider lie beyond the final ball: left out, it is exact.
  for (const auto& [d, index] : found)
    if (d < result.reach_sq) near->push_back(index);
  *distance_sq = result.best_distance_sq;
  *radius_m = std::sqrt(result.reach_sq);
  return static_cast<int>(result.best_index);
}

bool ReferenceModel::anyWithin(const Eigen::Vector3f& query, float max_distance_sq) const {
  std::uint32_t index = 0;
  float distance_sq = 0.0f;
  nanoflann::KNNResultSet<float, std::uint32_t> result(1);
  result.init(&index, &distance_sq);
  tree_->index.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return distance_sq <= max_distance_sq;
}

VisibilityPredictor::VisibilityPredictor(const ardsim_lidar::Intrinsics& intrinsics,
                                         const VisibilityOptions& options)
    : intrinsics_(intrinsics), options_(options) {
  validate(options);
  grid_width_ = (intrinsics.width + options.cell_px - 1) / options.cell_px;
  grid_height_ = (intrinsics.height + options.cell_px - 1) / options.cell_px;
  margin_cells_ = static_cast<int>(std::ceil(options.margin_px / options.cell_px));
  padded_width_ = grid_width_ + 2 * margin_cells_;
  padded_height_ = grid_height_ + 2 * margin_cells_;
}

int VisibilityPredictor::predict(const ReferenceModel& model, const Eigen::Isometry3d& T_lidar_target,
                                 std::vector<std::uint8_t>* visible) {
  visible->assign(model.size(), 0);
  const float inf = std::numeric_limits<float>::infinity();
  depth_.assign(static_cast<std::size_t>(padded_width_) * padded_height_, inf);
  candidates_.clear();
  const Eigen::Matrix3f R = T_lidar_target.linear().cast<float>();
  const Eigen::Vector3f t = T_lidar_target.translation().cast<float>();
  const Eigen::Vector3f eye = -(R.transpose() * t);  // the sensor, target frame
  const float fx = static_cast<float>(intrinsics_.fx);
  const float fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx);
  const float cy = static_cast<float>(intrinsics_.cy);
  const float cell = static_cast<float>(options_.cell_px);
  const float margin = static_cast<float>(options_.margin_px);
  const float u_min = -0.5f - margin, u_max = intrinsics_.width - 0.5f + margin;
  const float v_min = -0.5f - margin, v_max = intrinsics_.height - 0.5f + margin;
  // Frustum side planes (with the margin) as unit normals pointing inside, for the chunk sphere test.
  const float tan_x = (cx + 0.5f + margin) / fx;
  const float tan_y = (cy + 0.5f + margin) / fy;
  const Eigen::Vector3f planes[4] = {
      Eigen::Vector3f(1, 0, tan_x).normalized(), Eigen::Vector3f(-1, 0, tan_x).normalized(),
      Eigen::Vector3f(0, 1, tan_y).normalized(), Eigen::Vector3f(0, -1, tan_y).normalized()};
  const float offset = static_cast<float>(margin_cells_);
  for (const ReferenceModel::Chunk& chunk : model.chunks()) {
    const Eigen::Vector3f c = R * chunk.centre + t;
    if (c.z() + chunk.radius < 0.05f) continue;
    bool outside = false;
    for (const Eigen::Vector3f& plane : planes) outside = outside || plane.dot(c) < -chunk.radius;
    if (outside) continue;
    for (std::uint32_t i = chunk.begin; i < chunk.end; ++i) {
      const ReferenceModel::Patch& patch = model.patches()[i];
      // Back face (seen from behind), tested in target coordinates before the transform: half the patches.
      if (patch.normal.dot(patch.centre - eye) >= 0.0f) continue;
      const Eigen::Vector3f p = R * patch.centre + t;
      if (p.z() < 0.05f) continue;
      const float inv_z = 1.0f / p.z();
      const float u = fx * p.x() * inv_z + cx;
      const float v = fy * p.y() * inv_z + cy;
      const float radius_px = patch.radius * fx * inv_z;
      if (u + radius_px < u_min || u - radius_px >= u_max || v + radius_px < v_min || v - radius_px >= v_max)
        continue;
      const int cu = static_cast<int>(std::floor((u + 0.5f) / cell + offset));
      const int cv = static_cast<int>(std::floor((v + 0.5f) / cell + offset));
      // Splat the patch over the cells it covers, so that it hides what is behind it.
      const int radius = std::min(16, static_cast<int>(radius_px / cell + 0.5f));
      for (int y = std::max(0, cv - radius); y <= std::min(padded_height_ - 1, cv + radius); ++y)
        for (int x = std::max(0, cu - radius); x <= std::min(padded_width_ - 1, cu + radius); ++x) {
          float& d = depth_[static_cast<std::size_t>(y) * padded_width_ + x];
          d = std::min(d, p.z());
        }
      const int cell_index =
          std::clamp(cv, 0, padded_height_ - 1) * padded_width_ + std::clamp(cu, 0, padded_width_ - 1);
      candidates_.push_back({i, cell_index, p.z() - patch.radius});
    }
  }
  int count = 0;
  for (const Candidate& candidate : candidates_) {
    // A surface inclined in a cell spans a depth range: allow a few cells' width besides the fixed tolerance.
    const float tolerance =
        std::max(static_cast<float>(options_.depth_tolerance_m), 3.0f * cell * candidate.depth / fx);
    if (candidate.depth <= depth_[candidate.cell] + tolerance) {
      const ReferenceModel::Patch& patch = model.patches()[candidate.patch];
      std::fill(visible->begin() + patch.begin, visible->begin() + patch.end, 1);
      count += static_cast<int>(patch.end - patch.begin);
    }
  }
  nearest_depth_ = *std::min_element(depth_.begin(), depth_.end());
  model_depth_.assign(static_cast<std::size_t>(grid_width_) * grid_height_, inf);
  for (int y = 0; y < grid_height_; ++y)
    for (int x = 0; x < grid_width_; ++x)
      model_depth_[static_cast<std::size_t>(y) * grid_width_ + x] =
          depth_[static_cast<std::size_t>(y + margin_cells_) * padded_width_ + x + margin_cells_];
  return count;
}

}  // namespace ardsim_pose
