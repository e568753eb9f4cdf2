#include "ardsim_pose/reference_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include <nanoflann.hpp>

#include "ardsim_pose/require_option.h"

namespace ardsim_pose {

namespace {

// A patch's back-face test, n . (centre - eye) in floats, is within a few roundings (2^-24 relative) of the
// exact value times |centre|_1 + |eye|_1: a plane run decides for all its patches beyond 1e-5 of that.
constexpr float kPlaneRunSlack = 1e-5f;

// floor(x) as an int, for x within int's range: without SSE4.1's rounding instruction (baseline x86-64)
// std::floor expands to a longer sequence, ~12 % of a prediction's instructions as two per patch.
int floorToInt(float x) {
  const int truncated = static_cast<int>(x);
  return truncated - (x < static_cast<float>(truncated) ? 1 : 0);
}

// Depth, image position and radius in pixels of n patches (centres CX, CY, CZ, radii) at T = (R, t), in one
// pass that GCC vectorizes: the same operations in the same order as one patch at a time, so the same floats.
void projectPatches(const float* __restrict CX, const float* __restrict CY, const float* __restrict CZ,
                    const float* __restrict radii, int n, const Eigen::Matrix3f& R, const Eigen::Vector3f& t,
                    float fx, float fy, float cx, float cy, float* __restrict z, float* __restrict u,
                    float* __restrict v, float* __restrict radius_px) {
  const float r00 = R(0, 0), r01 = R(0, 1), r02 = R(0, 2), r10 = R(1, 0), r11 = R(1, 1), r12 = R(1, 2),
              r20 = R(2, 0), r21 = R(2, 1), r22 = R(2, 2);
  const float tx = t.x(), ty = t.y(), tz = t.z();
  // A 1 the compiler cannot see: with a constant numerator it turns 1 / max(z, 0.05) into a branch between
  // two divisions (one of which may trap, so not vectorized).
  const volatile float opaque_one = 1.0f;
  const float one = opaque_one;
  for (int k = 0; k < n; ++k) {
    const float depth = r20 * CX[k] + r21 * CY[k] + r22 * CZ[k] + tz;
    // 1 / z where z >= 0.05 (the others are skipped by the caller).
    const float inv_z = one / std::max(depth, 0.05f);
    z[k] = depth;
    u[k] = fx * (r00 * CX[k] + r01 * CY[k] + r02 * CZ[k] + tx) * inv_z + cx;
    v[k] = fy * (r10 * CX[k] + r11 * CY[k] + r12 * CZ[k] + ty) * inv_z + cy;
    radius_px[k] = radii[k] * fx * inv_z;
  }
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
  requireOption(
      std::isfinite(o.spacing_at_port_m) && o.spacing_at_port_m >= 0.005 && o.spacing_at_port_m <= 1.0,
      "model/spacing_at_port_m", o.spacing_at_port_m, "0.005 .. 1");
  requireOption(
      std::isfinite(o.spacing_growth_per_m) && o.spacing_growth_per_m >= 0.0 && o.spacing_growth_per_m <= 0.1,
      "model/spacing_growth_per_m", o.spacing_growth_per_m, "0 .. 0.1");
  requireOption(
      std::isfinite(o.max_spacing_m) && o.max_spacing_m >= o.spacing_at_port_m && o.max_spacing_m <= 2.0,
      "model/max_spacing_m", o.max_spacing_m, "spacing_at_port_m .. 2");
  requireOption(std::isfinite(o.patch_spacings) && o.patch_spacings >= 1.0 && o.patch_spacings <= 20.0,
                "model/patch_spacings", o.patch_spacings, "1 .. 20");
  requireOption(std::isfinite(o.chunk_size_m) && o.chunk_size_m >= 0.5 && o.chunk_size_m <= 50.0,
                "model/chunk_size_m", o.chunk_size_m, "0.5 .. 50");
}

void validate(const VisibilityOptions& o) {
  requireOption(o.cell_px >= 1 && o.cell_px <= 32, "visibility/cell_px", o.cell_px, "1 .. 32");
  requireOption(std::isfinite(o.margin_px) && o.margin_px >= 0.0 && o.margin_px <= 256.0,
                "visibility/margin_px", o.margin_px, "0 .. 256");
  requireOption(
      std::isfinite(o.depth_tolerance_m) && o.depth_tolerance_m > 0.0 && o.depth_tolerance_m <= 10.0,
      "visibility/depth_tolerance_m", o.depth_tolerance_m, "> 0 .. 10");
  requireOption(
      std::isfinite(o.max_incidence_deg) && o.max_incidence_deg > 0.0 && o.max_incidence_deg <= 90.0,
      "visibility/max_incidence_deg", o.max_incidence_deg, "> 0 .. 90");
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

// The trees of a model with parts that turn (and of every model turned from it): the rigid points, and the
// articulated ones where they were sampled (with their normals there), each with the model's index of every
// point.
struct ReferenceModel::SplitTrees {
  struct Group {
    std::vector<Eigen::Vector3f> points;
    std::vector<std::uint32_t> model_index;
    std::unique_ptr<KdTree> tree;
  };
  Group rigid, articulated;
  std::vector<Eigen::Vector3f> articulated_normals;
  // Triangles of the articulated patches as sampled (index; a triangle listed again where its patches are
  // not consecutive: turned twice the same way).
  std::vector<std::pair<std::uint32_t, Triangle>> articulated_triangles;
  // The arrays of the last turned model gone, for the next turn to copy into: allocated anew (~11 MB for
  // Hubble) they cost one turn in three ~30 ms of page faults. One set: a turn needs one while the model
  // before it is still in use.
  mutable std::mutex spare_mutex;
  mutable std::optional<ReferenceModel::Arrays> spare;
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

// Whether any point lies within a distance: the search prunes beyond it and stops at the first found (the
// nearest point, searched in full, cost 5-7 % of a tracking frame at 10 m).
struct AnyWithinResult {
  float reach_sq;  // just above the distance squared: the tree passes only points strictly nearer
  bool found = false;
  bool addPoint(float distance_sq, std::uint32_t) {
    found = distance_sq < reach_sq;
    return !found;
  }
  float worstDist() const { return reach_sq; }
  bool full() const { return found; }
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

// A patch's bounding radius: its samples' box, and half a spacing beyond (the surface the samples stand for).
float patchRadius(const Eigen::AlignedBox3f& samples, float spacing) {
  return 0.5f * samples.diagonal().norm() + 0.5f * spacing;
}

// A chunk's bounding sphere: its samples' box's centre and half its diagonal.
void boundChunk(const Eigen::AlignedBox3f& samples, ReferenceModel::Chunk* chunk) {
  chunk->centre = samples.center();
  chunk->radius = 0.5f * samples.diagonal().norm();
}

// A search of one group of the points (ReferenceModel::SplitTrees): its tree's indices made the model's.
template <class Result>
struct GroupResult {
  Result& inner;
  const std::uint32_t* model_index;
  bool addPoint(float distance_sq, std::uint32_t index) {
    return inner.addPoint(distance_sq, model_index[index]);
  }
  float worstDist() const { return inner.worstDist(); }
  bool full() const { return inner.full(); }
};

// How far the turn of a query and of the points may round their distance apart (coordinates within ~20 m).
constexpr float kTurnRoundingM = 1e-4f;

// A search of the articulated points where they were sampled, the query turned there: the distances are
// computed anew to the turned points (as the tree would: every search finds the same nearest point), and
// the search reaches a hair further, for the rounding of the turn.
template <class Result>
struct TurnedResult {
  Result& inner;
  const std::uint32_t* model_index;
  const Eigen::Vector3f* model_points;
  Eigen::Vector3f query;
  bool addPoint(float, std::uint32_t index) {
    const std::uint32_t i = model_index[index];
    return inner.addPoint(treeDistanceSq(query, model_points[i]), i);
  }
  float worstDist() const {
    const float reach = std::sqrt(inner.worstDist()) + kTurnRoundingM;
    return reach * reach;
  }
  bool full() const { return inner.full(); }
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
  arrays_.triangles.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& corners : mesh.triangles)
    arrays_.triangles.push_back(
        {mesh.vertices[corners[0]], mesh.vertices[corners[1]], mesh.vertices[corners[2]]});

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
  arrays_.points.reserve(points.size());
  arrays_.normals.reserve(points.size());
  arrays_.spacing.reserve(points.size());
  std::vector<Eigen::Vector3f> patch_centres, patch_normals;
  std::vector<float> patch_radii;
  for (const auto& chunk_entry : chunk_members) {
    Chunk chunk;
    chunk.begin = static_cast<std::uint32_t>(arrays_.patches.size());
    Eigen::AlignedBox3f chunk_box;
    for (const std::vector<std::uint32_t>* members : chunk_entry.second) {
      Patch patch;
      patch.begin = static_cast<std::uint32_t>(arrays_.points.size());
      const std::uint32_t triangle = triangle_of[members->front()];
      arrays_.patch_articulated.push_back(triangle < mesh.triangle_part.size() &&
                                          mesh.triangle_part[triangle] < mesh.parts.size() &&
                                          mesh.parts[mesh.triangle_part[triangle]].articulated);
      patch_normals.push_back(normals[members->front()]);
      arrays_.patch_triangle.push_back(triangle);
      Eigen::AlignedBox3f box;
      for (std::uint32_t i : *members) {
        arrays_.points.push_back(points[i]);
        arrays_.normals.push_back(normals[i]);
        arrays_.spacing.push_back(spacing[i]);
        box.extend(points[i]);
      }
      patch.end = static_cast<std::uint32_t>(arrays_.points.size());
      patch_centres.push_back(box.center());
      patch_radii.push_back(patchRadius(box, spacing[members->front()]));
      arrays_.patches.push_back(patch);
      chunk_box.extend(box);
    }
    chunk.end = static_cast<std::uint32_t>(arrays_.patches.size());
    boundChunk(chunk_box, &chunk);
    arrays_.chunks.push_back(chunk);
  }
  // Arrays for vectorized loops over ranges of patches and points (the points also stay as vectors: the tree
  // and the ICP read them one at a time).
  arrays_.patch_radii =
      Eigen::Map<const Eigen::ArrayXf>(patch_radii.data(), static_cast<Eigen::Index>(patch_radii.size()));
  for (int axis = 0; axis < 3; ++axis) {
    arrays_.patch_centres[axis].resize(static_cast<Eigen::Index>(patch_centres.size()));
    arrays_.patch_normals[axis].resize(static_cast<Eigen::Index>(patch_normals.size()));
    for (std::size_t i = 0; i < patch_centres.size(); ++i) {
      arrays_.patch_centres[axis][static_cast<Eigen::Index>(i)] = patch_centres[i][axis];
      arrays_.patch_normals[axis][static_cast<Eigen::Index>(i)] = patch_normals[i][axis];
    }
    arrays_.coordinates[axis].resize(static_cast<Eigen::Index>(arrays_.points.size()));
    for (std::size_t i = 0; i < arrays_.points.size(); ++i)
      arrays_.coordinates[axis][static_cast<Eigen::Index>(i)] = arrays_.points[i][axis];
  }
  for (Chunk& chunk : arrays_.chunks) {
    chunk.run_begin = static_cast<std::uint32_t>(arrays_.plane_runs.size());
    for (std::uint32_t p = chunk.begin; p < chunk.end;) {
      PlaneRun run;
      run.begin = p;
      while (p < chunk.end && arrays_.patch_triangle[p] == arrays_.patch_triangle[run.begin]) ++p;
      run.end = p;
      boundPlaneRun(&run);
      arrays_.plane_runs.push_back(run);
    }
    chunk.run_end = static_cast<std::uint32_t>(arrays_.plane_runs.size());
  }
  arrays_.point_articulated.resize(arrays_.points.size());
  for (std::size_t p = 0; p < arrays_.patches.size(); ++p)
    std::fill(arrays_.point_articulated.begin() + arrays_.patches[p].begin,
              arrays_.point_articulated.begin() + arrays_.patches[p].end, arrays_.patch_articulated[p]);
  if (std::find(arrays_.patch_articulated.begin(), arrays_.patch_articulated.end(), 1) ==
      arrays_.patch_articulated.end()) {
    tree_ = std::make_unique<KdTree>(&arrays_.points);
    return;
  }
  auto split = std::make_shared<SplitTrees>();
  for (std::size_t p = 0; p < arrays_.patches.size(); ++p) {
    SplitTrees::Group& group = arrays_.patch_articulated[p] ? split->articulated : split->rigid;
    const std::uint32_t triangle = arrays_.patch_triangle[p];
    if (arrays_.patch_articulated[p] &&
        (split->articulated_triangles.empty() || split->articulated_triangles.back().first != triangle))
      split->articulated_triangles.emplace_back(triangle, arrays_.triangles[triangle]);
    for (std::uint32_t i = arrays_.patches[p].begin; i < arrays_.patches[p].end; ++i) {
      group.points.push_back(arrays_.points[i]);
      group.model_index.push_back(i);
      if (arrays_.patch_articulated[p]) split->articulated_normals.push_back(arrays_.normals[i]);
    }
  }
  split->rigid.tree = std::make_unique<KdTree>(&split->rigid.points);
  split->articulated.tree = std::make_unique<KdTree>(&split->articulated.points);
  split_ = std::move(split);
}

ReferenceModel::~ReferenceModel() {
  if (!split_) return;
  const std::lock_guard<std::mutex> lock(split_->spare_mutex);
  split_->spare = std::move(arrays_);
}

std::shared_ptr<const ReferenceModel> ReferenceModel::withArticulatedTurned(const Eigen::Vector3d& origin,
                                                                            const Eigen::Vector3d& axis,
                                                                            double angle_rad) const {
  std::shared_ptr<ReferenceModel> turned(new ReferenceModel());
  ReferenceModel& m = *turned;
  if (split_) {
    const std::lock_guard<std::mutex> lock(split_->spare_mutex);
    if (split_->spare) {
      m.arrays_ = std::move(*split_->spare);
      split_->spare.reset();
    }
  }
  // Copied into the spare's memory when there is one (the sizes are the same).
  m.arrays_ = arrays_;
  m.split_ = split_;
  m.T_model_sampled_ = Eigen::Translation3d(origin) * Eigen::AngleAxisd(angle_rad, axis) *
                       Eigen::Translation3d(-origin) * T_model_sampled_;
  m.T_sampled_model_ = m.T_model_sampled_.inverse().cast<float>();
  if (!split_) {  // nothing turns (the tree reads the points it was built over)
    m.tree_ = std::make_unique<KdTree>(&m.arrays_.points);
    return turned;
  }
  // Turned from where they were sampled (turns do not add up their rounding).
  const Eigen::Isometry3f T = m.T_model_sampled_.cast<float>();
  const SplitTrees::Group& articulated = m.split_->articulated;
  for (std::size_t k = 0; k < articulated.points.size(); ++k) {
    const std::uint32_t i = articulated.model_index[k];
    m.arrays_.points[i] = T * articulated.points[k];
    m.arrays_.normals[i] = T.linear() * m.split_->articulated_normals[k];
    for (int axis_index = 0; axis_index < 3; ++axis_index)
      m.arrays_.coordinates[axis_index][i] = m.arrays_.points[i][axis_index];
  }
  for (const auto& [index, triangle] : m.split_->articulated_triangles)
    for (int corner = 0; corner < 3; ++corner) m.arrays_.triangles[index][corner] = T * triangle[corner];
  for (Chunk& chunk : m.arrays_.chunks) {
    bool turned_any = false;
    for (std::uint32_t p = chunk.begin; p < chunk.end; ++p) {
      if (!m.arrays_.patch_articulated[p]) continue;
      turned_any = true;
      const Patch& patch = m.arrays_.patches[p];
      // Bounded as the constructor bounds a patch; its normal is its first sample's.
      Eigen::AlignedBox3f box;
      for (std::uint32_t i = patch.begin; i < patch.end; ++i) box.extend(m.arrays_.points[i]);
      const Eigen::Vector3f centre = box.center();
      for (int axis_index = 0; axis_index < 3; ++axis_index) {
        m.arrays_.patch_centres[axis_index][p] = centre[axis_index];
        m.arrays_.patch_normals[axis_index][p] = m.arrays_.normals[patch.begin][axis_index];
      }
      m.arrays_.patch_radii[p] = patchRadius(box, m.arrays_.spacing[patch.begin]);
    }
    if (!turned_any) continue;
    for (std::uint32_t r = chunk.run_begin; r < chunk.run_end; ++r)
      if (m.arrays_.patch_articulated[m.arrays_.plane_runs[r].begin])
        m.boundPlaneRun(&m.arrays_.plane_runs[r]);
    Eigen::AlignedBox3f chunk_box;
    for (std::uint32_t i = m.arrays_.patches[chunk.begin].begin; i < m.arrays_.patches[chunk.end - 1].end;
         ++i)
      chunk_box.extend(m.arrays_.points[i]);
    boundChunk(chunk_box, &chunk);
  }
  return turned;
}

void ReferenceModel::boundPlaneRun(PlaneRun* run) const {
  for (int axis = 0; axis < 3; ++axis) run->normal[axis] = arrays_.patch_normals[axis][run->begin];
  double offset_min = std::numeric_limits<double>::infinity(), offset_max = -offset_min;
  float extent = 0.0f;
  for (std::uint32_t p = run->begin; p < run->end; ++p) {
    const Eigen::Vector3f centre(arrays_.patch_centres[0][p], arrays_.patch_centres[1][p],
                                 arrays_.patch_centres[2][p]);
    const double offset = run->normal.cast<double>().dot(centre.cast<double>());
    offset_min = std::min(offset_min, offset);
    offset_max = std::max(offset_max, offset);
    extent = std::max(extent, centre.lpNorm<1>());
  }
  run->offset_min = static_cast<float>(offset_min);
  run->offset_max = static_cast<float>(offset_max);
  run->extent = extent;
}

template <class Result>
void ReferenceModel::searchRigid(Result& result, const Eigen::Vector3f& query) const {
  if (tree_) {
    tree_->index.findNeighbors(result, query.data(), nanoflann::SearchParams());
    return;
  }
  GroupResult<Result> group{result, split_->rigid.model_index.data()};
  split_->rigid.tree->index.findNeighbors(group, query.data(), nanoflann::SearchParams());
}

template <class Result>
void ReferenceModel::searchTurned(Result& result, const Eigen::Vector3f& query) const {
  if (!split_) return;
  TurnedResult<Result> turned{result, split_->articulated.model_index.data(), arrays_.points.data(), query};
  const Eigen::Vector3f query_sampled = T_sampled_model_ * query;
  split_->articulated.tree->index.findNeighbors(turned, query_sampled.data(), nanoflann::SearchParams());
}

int ReferenceModel::nearestVisible(const Eigen::Vector3f& query, float max_distance_sq,
                                   const std::vector<std::uint8_t>& visible, float* distance_sq) const {
  NearestVisibleResult result{visible.data(), max_distance_sq};
  searchRigid(result, query);
  searchTurned(result, query);
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
  searchRigid(result, query);
  searchTurned(result, query);
  // Points collected while the reach was still wider lie beyond the final ball: left out, it is exact.
  for (const auto& [d, index] : found)
    if (d < result.reach_sq) near->push_back(index);
  *distance_sq = result.best_distance_sq;
  *radius_m = std::sqrt(result.reach_sq);
  return static_cast<int>(result.best_index);
}

bool ReferenceModel::anyWithin(const Eigen::Vector3f& query, float max_distance_sq) const {
  AnyWithinResult result{std::nextafter(max_distance_sq, std::numeric_limits<float>::infinity())};
  searchRigid(result, query);
  if (!result.found) searchTurned(result, query);
  return result.found;
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
  const double cos_max_incidence = std::cos(options.max_incidence_deg * M_PI / 180.0);
  cos_max_incidence_sq_ =
      options.max_incidence_deg < 90.0 ? static_cast<float>(cos_max_incidence * cos_max_incidence) : 0.0f;
}

int VisibilityPredictor::predict(const ReferenceModel& model, const Eigen::Isometry3d& T_lidar_target,
                                 bool with_points, bool oblique) {
  const float cos_max_incidence_sq = oblique ? 0.0f : cos_max_incidence_sq_;
  // Clear the flags the last prediction set rather than every point's (that memset was 4 % of a 30 m frame).
  if (visible_.size() == model.size()) {
    for (const auto& [begin, end] : visible_ranges_)
      std::fill(visible_.begin() + begin, visible_.begin() + end, 0);
  } else {
    visible_.assign(model.size(), 0);
  }
  visible_ranges_.clear();
  visible_patches_.clear();
  const float inf = std::numeric_limits<float>::infinity();
  depth_.assign(static_cast<std::size_t>(padded_width_) * padded_height_, inf);
  if (candidates_.size() < model.patches().size()) candidates_.resize(model.patches().size());
  std::size_t candidate_count = 0;
  const Eigen::Matrix3f R = T_lidar_target.linear().cast<float>();
  const Eigen::Vector3f t = T_lidar_target.translation().cast<float>();
  const Eigen::Vector3f eye = -(R.transpose() * t);  // the sensor, target frame
  const float fx = static_cast<float>(intrinsics_.fx);
  const float fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx);
  const float cy = static_cast<float>(intrinsics_.cy);
  const float cell = static_cast<float>(options_.cell_px);
  const float inv_cell = 1.0f / cell;  // multiplied, not divided, per patch (exact for the default 4 px)
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
  const float eye_l1 = eye.lpNorm<1>();
  for (const ReferenceModel::Chunk& chunk : model.chunks()) {
    const Eigen::Vector3f c = R * chunk.centre + t;
    if (c.z() + chunk.radius < 0.05f) continue;
    bool outside = false;
    for (const Eigen::Vector3f& plane : planes) outside = outside || plane.dot(c) < -chunk.radius;
    if (outside) continue;
    // The chunk's patches' depth and image position in one pass, which GCC vectorizes (the same operations
    // in the same order as one patch at a time, so the same floats), then patch by patch.
    const Eigen::Index begin = chunk.begin, n = chunk.end - chunk.begin;
    if (depth_z_.size() < n) {
      for (Eigen::ArrayXf* a : {&depth_z_, &u_, &v_, &radius_px_}) a->resize(n);
    }
    const float* CX = model.patchCentres(0).data() + begin;
    const float* CY = model.patchCentres(1).data() + begin;
    const float* CZ = model.patchCentres(2).data() + begin;
    const float* radii = model.patchRadii().data() + begin;
    projectPatches(CX, CY, CZ, radii, static_cast<int>(n), R, t, fx, fy, cx, cy, depth_z_.data(), u_.data(),
                   v_.data(), radius_px_.data());
    const float *z = depth_z_.data(), *us = u_.data(), *vs = v_.data(), *radii_px = radius_px_.data();
    const auto U = u_.head(n), V = v_.head(n), P = radius_px_.head(n);
    // Every patch (back faces and those behind the sensor included) two cells inside the padded image: none
    // needs the bounds test or the clamps below (a floor and a rounding cost less than a cell each).
    const float inner = 2.0f * cell;
    const bool inside = (U - P).minCoeff() >= u_min + inner && (U + P).maxCoeff() <= u_max - inner &&
                        (V - P).minCoeff() >= v_min + inner && (V + P).maxCoeff() <= v_max - inner;
    const float* NX = model.patchNormals(0).data() + begin;
    const float* NY = model.patchNormals(1).data() + begin;
    const float* NZ = model.patchNormals(2).data() + begin;
    // Compiled twice: with and without the bounds test and clamps.
    const auto splat = [&](auto inside_constant) {
      constexpr bool kInside = decltype(inside_constant)::value;
      for (std::uint32_t r = chunk.run_begin; r < chunk.run_end; ++r) {
        // Back faces (seen from behind: half the patches) by their triangle's plane where the sensor is
        // clearly on one side of it (by more than a patch's own test may round; every ISS run from 9 to 99 m
        // on the docking axis), else patch by patch. (Also skipping the back runs' arithmetic above: no
        // faster.)
        const ReferenceModel::PlaneRun& run = model.planeRuns()[r];
        const float eye_offset = run.normal.dot(eye);
        const float slack = kPlaneRunSlack * (run.extent + eye_l1);
        if (run.offset_min - eye_offset > slack) continue;
        const bool front = eye_offset - run.offset_max > slack;
        for (Eigen::Index k = run.begin - begin; k < run.end - begin; ++k) {
          if (!front &&
              NX[k] * (CX[k] - eye.x()) + NY[k] * (CY[k] - eye.y()) + NZ[k] * (CZ[k] - eye.z()) >= 0.0f)
            continue;
          if (z[k] < 0.05f) continue;
          const std::uint32_t i = static_cast<std::uint32_t>(begin + k);
          const float u = us[k], v = vs[k];
          const float depth = z[k], radius_px = radii_px[k];
          if (!kInside && (u + radius_px < u_min || u - radius_px >= u_max || v + radius_px < v_min ||
                           v - radius_px >= v_max))
            continue;
          // Inside, the cell coordinates are at least 2 (two cells inside the padded image): truncation
          // floors.
          const float cell_u = (u + 0.5f) * inv_cell + offset, cell_v = (v + 0.5f) * inv_cell + offset;
          const int cu = kInside ? static_cast<int>(cell_u) : floorToInt(cell_u);
          const int cv = kInside ? static_cast<int>(cell_v) : floorToInt(cell_v);
          // Splat the patch over the cells it covers, so that it hides what is behind it.
          const int radius = std::min(16, static_cast<int>(radius_px * inv_cell + 0.5f));
          const int x0 = kInside ? cu - radius : std::max(0, cu - radius);
          const int x1 = kInside ? cu + radius : std::min(padded_width_ - 1, cu + radius);
          const int y0 = kInside ? cv - radius : std::max(0, cv - radius);
          const int y1 = kInside ? cv + radius : std::min(padded_height_ - 1, cv + radius);
          float* row = depth_.data() + static_cast<std::size_t>(y0) * padded_width_;
          if (x1 - x0 == 2 && y1 - y0 == 2) {  // most patches from 30 m in: 3 x 3 cells, unrolled
            for (int y = 0; y < 3; ++y, row += padded_width_) {
              row[x0] = std::min(row[x0], depth);
              row[x0 + 1] = std::min(row[x0 + 1], depth);
              row[x0 + 2] = std::min(row[x0 + 2], depth);
            }
          } else if (x0 == x1 && y0 == y1) {  // one cell: a patch under 2 px across
            row[x0] = std::min(row[x0], depth);
          } else {
            for (int y = y0; y <= y1; ++y, row += padded_width_)
              for (int x = x0; x <= x1; ++x) row[x] = std::min(row[x], depth);
          }
          const int cell_index = kInside ? cv * padded_width_ + cu
                                         : std::clamp(cv, 0, padded_height_ - 1) * padded_width_ +
                                               std::clamp(cu, 0, padded_width_ - 1);
          if (with_points) {
            // Seen more obliquely than max_incidence_deg the patch returns nothing: it hides what is behind
            // (splatted above) but is no candidate. Kept as one, the rim of a face seen end-on matched the
            // grazing wall beside it: the ISS's docking adapter from 7-10 m, its port 6-8 mm off across the
            // boresight on average.
            const float dx = CX[k] - eye.x(), dy = CY[k] - eye.y(), dz = CZ[k] - eye.z();
            const float along = NX[k] * dx + NY[k] * dy + NZ[k] * dz;
            if (along * along >= cos_max_incidence_sq * (dx * dx + dy * dy + dz * dz))
              candidates_[candidate_count++] = {i, cell_index, depth - radii[k]};
          }
        }
      }
    };
    if (inside)
      splat(std::true_type{});
    else
      splat(std::false_type{});
  }
  int count = 0;
  for (std::size_t c = 0; c < candidate_count; ++c) {
    const Candidate& candidate = candidates_[c];
    // A surface inclined in a cell spans a depth range: allow a few cells' width besides the fixed tolerance.
    const float tolerance =
        std::max(static_cast<float>(options_.depth_tolerance_m), 3.0f * cell * candidate.depth / fx);
    if (candidate.depth <= depth_[candidate.cell] + tolerance) {
      const ReferenceModel::Patch& patch = model.patches()[candidate.patch];
      // Consecutive patches' points join (the candidates come in the order of the patches).
      if (!visible_ranges_.empty() && visible_ranges_.back().second == patch.begin)
        visible_ranges_.back().second = patch.end;
      else
        visible_ranges_.push_back({patch.begin, patch.end});
      count += static_cast<int>(patch.end - patch.begin);
      visible_patches_.push_back(candidate.patch);
    }
  }
  for (const auto& [begin, end] : visible_ranges_)
    std::fill(visible_.begin() + begin, visible_.begin() + end, 1);
  nearest_depth_ = *std::min_element(depth_.begin(), depth_.end());
  model_depth_.assign(static_cast<std::size_t>(grid_width_) * grid_height_, inf);
  for (int y = 0; y < grid_height_; ++y)
    for (int x = 0; x < grid_width_; ++x)
      model_depth_[static_cast<std::size_t>(y) * grid_width_ + x] =
          depth_[static_cast<std::size_t>(y + margin_cells_) * padded_width_ + x + margin_cells_];
  return count;
}

namespace {
// Bins of about kBinDepthM / depth pixels (1 to 4: 1 px from 60 m out, 2 px at 30 m, 4 px from 10 m in):
// per search 1-3 px bins were cheapest, but a frame also bins every visible point into them and sums over
// every bin; with that, the benchmark's 10 m frames were 6 % faster than with 2 px there (and 1 px at
// 30 m), 30 and 100 m within noise. A search reads at most kMaxWindowBins bins on each side of the query's
// (a window of 1-4 bins: slower, the tree answers too many).
constexpr double kBinDepthM = 45.0;
constexpr int kMaxWindowBins = 16;
// Points nearer the sensor are binned through this depth, so anywhere: a search counts them at least the
// difference away.
constexpr float kNearestDepthM = 0.05f;
}  // namespace

VisiblePointGrid::VisiblePointGrid(const ardsim_lidar::Intrinsics& intrinsics, double margin_px)
    : intrinsics_(intrinsics), pad_px_(static_cast<int>(std::ceil(margin_px))) {
  const double tan_x =
      (std::max(intrinsics.cx, intrinsics.width - intrinsics.cx) + 0.5 + pad_px_) / intrinsics.fx;
  const double tan_y =
      (std::max(intrinsics.cy, intrinsics.height - intrinsics.cy) + 0.5 + pad_px_) / intrinsics.fy;
  min_cos_sq_ = static_cast<float>(1.0 / (1.0 + tan_x * tan_x + tan_y * tan_y));
}

void VisiblePointGrid::build(const ReferenceModel& model, const std::vector<PointRange>& ranges,
                             const Eigen::Isometry3d& T_lidar_target, double depth_m) {
  bin_px_ = std::clamp(static_cast<int>(std::lround(kBinDepthM / std::max(depth_m, 1.0))), 1, 4);
  bins_wide_ = (intrinsics_.width + 2 * pad_px_ + bin_px_ - 1) / bin_px_;
  bins_high_ = (intrinsics_.height + 2 * pad_px_ + bin_px_ - 1) / bin_px_;
  R_ = T_lidar_target.linear().cast<float>();
  t_ = T_lidar_target.translation().cast<float>();
  // The points' bins in one pass over each range, which GCC vectorizes (the visible points are tens of
  // thousands a prediction; as four Eigen array passes through scratch arrays the binning of a 30 m frame
  // took 2.31 M instructions, now 1.98 M), then a counting sort by bin. The same operations in the same order
  // as a point at a time.
  const float inv_bin = 1.0f / bin_px_;
  const float fx = static_cast<float>(intrinsics_.fx) * inv_bin,
              fy = static_cast<float>(intrinsics_.fy) * inv_bin;
  const float cx = (static_cast<float>(intrinsics_.cx) + 0.5f + pad_px_) * inv_bin;
  const float cy = (static_cast<float>(intrinsics_.cy) + 0.5f + pad_px_) * inv_bin;
  const float wide = static_cast<float>(bins_wide_), high = static_cast<float>(bins_high_);
  const float* px = model.coordinates(0).data();
  const float* py = model.coordinates(1).data();
  const float* pz = model.coordinates(2).data();
  const float r00 = R_(0, 0), r01 = R_(0, 1), r02 = R_(0, 2), r10 = R_(1, 0), r11 = R_(1, 1), r12 = R_(1, 2),
              r20 = R_(2, 0), r21 = R_(2, 1), r22 = R_(2, 2);
  const float tx = t_(0), ty = t_(1), tz = t_(2);
  // Every point goes into a bin of the grid with a border of one bin around it: those beyond the padded
  // image into the border, which no search reads.
  const int stride = bins_wide_ + 2;
  std::size_t total = 0;
  for (const auto& [begin, end] : ranges) total += end - begin;
  bin_of_.resize(total);
  std::size_t n = 0;
  for (const auto& [begin, end] : ranges) {
    const int count = static_cast<int>(end - begin);
    const float *X = px + begin, *Y = py + begin, *Z = pz + begin;
    std::int32_t* bin_of = bin_of_.data() + n;
    for (int k = 0; k < count; ++k) {
      const float depth = r20 * X[k] + r21 * Y[k] + r22 * Z[k] + tz;
      const float z = depth < kNearestDepthM ? kNearestDepthM : depth;
      // Bin coordinates from the border's corner; >= 0, so the conversion truncates to the floor.
      float x = (r00 * X[k] + r01 * Y[k] + r02 * Z[k] + tx) * fx / z + (cx + 1.0f);
      float y = (r10 * X[k] + r11 * Y[k] + r12 * Z[k] + ty) * fy / z + (cy + 1.0f);
      x = x < 0.0f ? 0.0f : x;
      x = x > wide + 1.0f ? wide + 1.0f : x;
      y = y < 0.0f ? 0.0f : y;
      y = y > high + 1.0f ? high + 1.0f : y;
      bin_of[k] = static_cast<std::int32_t>(y) * stride + static_cast<std::int32_t>(x);
    }
    n += static_cast<std::size_t>(count);
  }
  // Counting sort: bin b's count at b + 2, summed, is where bin b begins at b + 1, and filling bin b moves
  // that to where bin b + 1 begins: then bin_begin_[b] is where bin b begins, with no pass to shift them
  // back.
  const std::size_t bins = static_cast<std::size_t>(stride) * (bins_high_ + 2);
  bin_begin_.assign(bins + 2, 0);
  std::uint32_t* counts = bin_begin_.data() + 2;
  for (std::size_t k = 0; k < n; ++k) ++counts[bin_of_[k]];
  std::uint32_t sum = 0;
  for (std::size_t b = 2; b < bins + 2; ++b) bin_begin_[b] = sum += bin_begin_[b];
  // Three more than the points: a search reads four at a time.
  for (std::vector<float>* c : {&bin_x_, &bin_y_, &bin_z_}) c->resize(n + 3);
  bin_index_.resize(n);
  std::uint32_t* next = bin_begin_.data() + 1;
  const Eigen::Vector3f* points = model.points().data();
  n = 0;
  for (const auto& [begin, end] : ranges) {
    for (std::uint32_t i = begin; i < end; ++i, ++n) {
      const std::uint32_t slot = next[bin_of_[n]]++;
      bin_x_[slot] = points[i].x();
      bin_y_[slot] = points[i].y();
      bin_z_[slot] = points[i].z();
      bin_index_[slot] = i;
    }
  }
}

bool VisiblePointGrid::nearest(const Eigen::Vector3f& query, float max_distance_sq, int* index,
                               float* distance_sq, float margin_m, float* radius_m,
                               std::vector<std::uint32_t>* near) const {
  const Eigen::Vector3f x = R_ * query + t_;
  if (!(x.z() > kNearestDepthM)) return false;
  const float u = static_cast<float>(intrinsics_.fx) * x.x() / x.z() + static_cast<float>(intrinsics_.cx) +
                  0.5f + pad_px_;
  const float v = static_cast<float>(intrinsics_.fy) * x.y() / x.z() + static_cast<float>(intrinsics_.cy) +
                  0.5f + pad_px_;
  const int bu = floorToInt(u / bin_px_), bv = floorToInt(v / bin_px_);
  if (bu < 0 || bv < 0 || bu >= bins_wide_ || bv >= bins_high_) return false;
  // A ray leaving a window of bins turns at least edge_px / f * cos^2 (the steepest image-plane motion per
  // radian of a ray in the padded image is f / cos^2 of its off-axis angle), so a point outside lies at
  // least |x| sin(that angle) from the query. Points beyond the padded image are in the border bins, which
  // no window reaches: they too lie outside it.
  const float range = 0.999f * x.norm();
  const float radians_per_px = min_cos_sq_ / static_cast<float>(std::max(intrinsics_.fx, intrinsics_.fy));
  found_.clear();  // window points that may be in the ball
  float best_sq = max_distance_sq;
  int best = -1;
  float ball_limit_sq = max_distance_sq;  // the ball cannot reach past the nearest distance and the margin
  const auto scan = [&](int ua, int ub, int va, int vb) {
    for (int y = va; y <= vb; ++y) {
      const std::size_t row = static_cast<std::size_t>(y + 1) * (bins_wide_ + 2) + 1;  // past the border
      const std::uint32_t end = bin_begin_[row + ub + 1];
      for (std::uint32_t k = bin_begin_[row + ua]; k < end; k += 4) {
        // Four points' distances at once, summed as treeDistanceSq sums them; one not within the limit as it
        // was before the four is not within it after any of them (it only shrinks). Lanes past end (the
        // next bins or the padding) are loaded but skipped.
        const Eigen::Array4f dx = Eigen::Map<const Eigen::Array4f>(bin_x_.data() + k) - query.x();
        const Eigen::Array4f dy = Eigen::Map<const Eigen::Array4f>(bin_y_.data() + k) - query.y();
        const Eigen::Array4f dz = Eigen::Map<const Eigen::Array4f>(bin_z_.data() + k) - query.z();
        const Eigen::Array4f d4 = dx * dx + dy * dy + dz * dz;
        if (!(d4 < ball_limit_sq).any()) continue;
        for (std::uint32_t lane = 0; lane < 4 && k + lane < end; ++lane) {
          const float d = d4[lane];
          if (!(d < ball_limit_sq)) continue;
          if (near != nullptr) found_.push_back({d, bin_index_[k + lane]});
          if (d < best_sq) {
            best_sq = d;
            best = static_cast<int>(bin_index_[k + lane]);
            const float limit = std::sqrt(d) + margin_m;
            ball_limit_sq = std::min(max_distance_sq, limit * limit);
          }
        }
      }
    }
  };
  // Widen the window ring by ring until what lies outside cannot be nearer than the best found (or, with
  // none found, lies beyond the gate).
  int u0 = bu, u1 = bu, v0 = bv, v1 = bv;
  scan(u0, u1, v0, v1);
  float reach = 0.0f;
  for (int w = 0;; ++w) {
    if (w > 0) {
      const int nu0 = std::max(0, bu - w), nu1 = std::min(bins_wide_ - 1, bu + w);
      const int nv0 = std::max(0, bv - w), nv1 = std::min(bins_high_ - 1, bv + w);
      if (nv0 < v0) scan(nu0, nu1, nv0, nv0);
      if (nv1 > v1) scan(nu0, nu1, nv1, nv1);
      if (nu0 < u0) scan(nu0, nu0, v0, v1);
      if (nu1 > u1) scan(nu1, nu1, v0, v1);
      u0 = nu0, u1 = nu1, v0 = nv0, v1 = nv1;
    }
    const float edge_px =
        std::min({u - u0 * bin_px_, (u1 + 1) * bin_px_ - u, v - v0 * bin_px_, (v1 + 1) * bin_px_ - v});
    // sin(a) >= a - a^3 / 6 for a >= 0 (a bound, not a libm call, in the hottest loop).
    const float a = std::min(edge_px * radians_per_px, 1.5707f);
    reach = std::min(range * (a - a * a * a * (1.0f / 6.0f)), 0.999f * (x.z() - kNearestDepthM));
    if (best_sq < reach * reach) break;
    if (w >= kMaxWindowBins) return false;
  }
  *index = best;
  *distance_sq = best_sq;
  if (near == nullptr) return true;
  float ball = best < 0 ? std::sqrt(max_distance_sq) : std::sqrt(best_sq) + margin_m;
  ball = std::min({ball, std::sqrt(max_distance_sq), reach});
  const float ball_sq = ball * ball;
  for (const auto& [d, i] : found_)
    if (d < ball_sq) near->push_back(i);
  *radius_m = ball;
  return true;
}

}  // namespace ardsim_pose
