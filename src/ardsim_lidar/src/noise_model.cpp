#include "ardsim_lidar/noise_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

// philox.h first: it defines the feature macros MicroURNG.hpp uses.
#include <Random123/philox.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Random123/MicroURNG.hpp>
#include <boost/random/normal_distribution.hpp>

namespace ardsim_lidar {

namespace {

constexpr float kNoReturn = std::numeric_limits<float>::quiet_NaN();

void require(bool ok, const std::string& name, double value, const std::string& allowed) {
  if (ok) return;
  std::ostringstream message;
  message << "noise/" << name << " = " << value << " is out of range: allowed " << allowed;
  throw std::invalid_argument(message.str());
}

// Per-frame randomness is counter-based (Philox4x64-10, Random123): every draw is a function of (seed, frame,
// stream, index) alone, so pixels can be processed in any order on any number of threads and a frame is the
// same whatever order frames are made in. Each pixel has its own stream (no per-block generator seeding).
using Philox = r123::Philox4x64;
using CounterRng = r123::MicroURNG<Philox>;

enum class Stream : std::uint64_t {
  kPixel = 0,  // index = pixel: return coin, mixed pixel, range noise
  kBloom = 1,  // index = saturated retro-reflector pixel: its spill into the neighbours
  kFrame = 2,  // index 0: background returns and hot pixels, drawn sequentially
};

CounterRng streamOf(std::uint64_t seed, std::uint64_t frame_index, Stream stream, std::uint64_t index) {
  // MicroURNG counts in the high 32 bits of the last counter word.
  return CounterRng(Philox::ctr_type{{index, frame_index, static_cast<std::uint64_t>(stream), 0}},
                    Philox::ukey_type{{seed, 0}});
}

// Uniform in [0, 1) from the top 53 bits.
double uniform01(CounterRng& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// Bloom sources are gathered per block of rows and joined in row order, so their order does not depend on
// scheduling.
constexpr int kRowsPerBlock = 16;

bool inClosed(double value, double low, double high) {
  return std::isfinite(value) && value >= low && value <= high;
}

std::uint32_t low32(std::uint64_t value) {
  return static_cast<std::uint32_t>(value & 0xffffffffu);
}
std::uint32_t high32(std::uint64_t value) {
  return static_cast<std::uint32_t>(value >> 32);
}

}  // namespace

void validate(const NoiseOptions& o) {
  require(std::isfinite(o.detection_range_m) && o.detection_range_m > 0.0, "detection_range_m",
          o.detection_range_m, "> 0");
  require(std::isfinite(o.saturation_range_m) && o.saturation_range_m > 0.0 &&
              o.saturation_range_m < o.detection_range_m,
          "saturation_range_m", o.saturation_range_m, "(0, detection_range_m)");
  require(inClosed(o.range_sigma_floor_m, 0.0, 10.0), "range_sigma_floor_m", o.range_sigma_floor_m,
          "[0, 10]");
  require(inClosed(o.range_sigma_weak_m, 0.0, 10.0), "range_sigma_weak_m", o.range_sigma_weak_m, "[0, 10]");
  require(inClosed(o.max_incidence_deg, 0.0, 90.0) && o.max_incidence_deg > 0.0, "max_incidence_deg",
          o.max_incidence_deg, "(0, 90]");
  require(inClosed(o.dead_pixel_fraction, 0.0, 1.0), "dead_pixel_fraction", o.dead_pixel_fraction, "[0, 1]");
  require(inClosed(o.hot_pixel_fraction, 0.0, 1.0 - o.dead_pixel_fraction), "hot_pixel_fraction",
          o.hot_pixel_fraction, "[0, 1 - dead_pixel_fraction]");
  require(inClosed(o.background_probability, 0.0, 1.0) && o.background_probability < 1.0,
          "background_probability", o.background_probability, "[0, 1)");
  require(inClosed(o.background_intensity, 0.0, 1.0), "background_intensity", o.background_intensity,
          "[0, 1]");
  require(std::isfinite(o.mixed_pixel_min_jump_m) && o.mixed_pixel_min_jump_m > 0.0, "mixed_pixel_min_jump_m",
          o.mixed_pixel_min_jump_m, "> 0");
  require(inClosed(o.mixed_pixel_probability, 0.0, 1.0), "mixed_pixel_probability", o.mixed_pixel_probability,
          "[0, 1]");
  require(std::isfinite(o.retro_gain) && o.retro_gain >= 1.0, "retro_gain", o.retro_gain, ">= 1");
  require(inClosed(o.retro_acceptance_deg, 0.0, 90.0) && o.retro_acceptance_deg > 0.0, "retro_acceptance_deg",
          o.retro_acceptance_deg, "(0, 90]");
  require(o.bloom_radius_px >= 0 && o.bloom_radius_px <= 16, "bloom_radius_px", o.bloom_radius_px, "0..16");
  require(inClosed(o.bloom_probability, 0.0, 1.0), "bloom_probability", o.bloom_probability, "[0, 1]");
  require(inClosed(o.saturation_range_bias_m, -1.0, 1.0), "saturation_range_bias_m",
          o.saturation_range_bias_m, "[-1, 1]");
}

std::size_t LidarFrame::returnCount() const {
  return static_cast<std::size_t>(
      std::count_if(range_m.begin(), range_m.end(), [](float range) { return std::isfinite(range); }));
}

NoiseModel::NoiseModel(const SensorOptions& sensor, const NoiseOptions& options, std::uint64_t seed)
    : sensor_(sensor),
      options_(options),
      seed_(seed),
      cos_max_incidence_(std::cos(options.max_incidence_deg * M_PI / 180.0)),
      cos_retro_acceptance_(std::cos(options.retro_acceptance_deg * M_PI / 180.0)),
      saturation_strength_(std::pow(options.detection_range_m / options.saturation_range_m, 2)) {
  validate(sensor);
  validate(options);
  const std::size_t pixel_count = static_cast<std::size_t>(sensor.width) * sensor.height;
  dead_.assign(pixel_count, 0);
  hot_.assign(pixel_count, 0);
  // One draw per pixel whatever the switches, so switching one effect off does not move the other's pixels.
  std::seed_seq sequence{low32(seed), high32(seed), 0u};
  std::mt19937_64 rng(sequence);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (std::size_t i = 0; i < pixel_count; ++i) {
    const double u = uniform(rng);
    if (u < options.dead_pixel_fraction) {
      dead_[i] = 1;
    } else if (u < options.dead_pixel_fraction + options.hot_pixel_fraction) {
      hot_[i] = 1;
    }
  }
}

double NoiseModel::strength(double reflectivity, double cos_incidence, bool retro_reflector,
                            double range_m) const {
  const double ratio = options_.detection_range_m / range_m;
  const double spreading = ratio * ratio;
  if (retro_reflector && options_.retro_reflectors && cos_incidence >= cos_retro_acceptance_)
    return options_.retro_gain * reflectivity * spreading;
  return reflectivity * cos_incidence * spreading;
}

double NoiseModel::rangeSigma(double strength) const {
  return options_.range_sigma_floor_m + options_.range_sigma_weak_m / std::sqrt(std::max(strength, 1e-12));
}

double NoiseModel::returnProbability(double strength) const {
  return 1.0 - std::exp(-strength);
}

double NoiseModel::intensity(double strength) const {
  return std::min(1.0, strength / saturation_strength_);
}

void NoiseModel::apply(const RenderedFrame& rendered,
                       const std::vector<ardsim_description::Material>& materials, std::uint64_t frame_index,
                       LidarFrame* frame) const {
  const int width = rendered.width;
  const int height = rendered.height;
  const int pixel_count = width * height;
  if (width != sensor_.width || height != sensor_.height)
    throw std::invalid_argument("noise model: rendered frame is " + std::to_string(width) + "x" +
                                std::to_string(height) + ", sensor is " + std::to_string(sensor_.width) +
                                "x" + std::to_string(sensor_.height));
  frame->width = width;
  frame->height = height;
  frame->range_m.assign(pixel_count, kNoReturn);
  frame->intensity.assign(pixel_count, kNoReturn);
  const float min_range = static_cast<float>(sensor_.min_range_m);
  const float max_range = static_cast<float>(sensor_.max_range_m);
  const ardsim_description::Material default_material;
  auto materialOf = [&](const SurfaceSample& sample) -> const ardsim_description::Material& {
    const int index = static_cast<int>(sample.material);
    return index >= 0 && index < static_cast<int>(materials.size()) ? materials[index] : default_material;
  };

  if (!options_.enabled) {
    for (int i = 0; i < pixel_count; ++i) {
      const SurfaceSample& sample = rendered.pixels[i];
      if (!(sample.range_m >= min_range && sample.range_m <= max_range)) continue;
      const ardsim_description::Material& material = materialOf(sample);
      frame->range_m[i] = sample.range_m;
      frame->intensity[i] = static_cast<float>(intensity(
          strength(material.reflectivity, sample.cos_incidence, material.retro_reflector, sample.range_m)));
    }
    return;
  }

  const int block_count = (height + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<std::vector<int>> saturated_retro_pixels(block_count);
  tbb::parallel_for(tbb::blocked_range<int>(0, block_count), [&](const tbb::blocked_range<int>& blocks) {
    // Ziggurat (Boost): a table look-up and one draw for most samples, where std's polar method needs a log.
    boost::random::normal_distribution<double> normal(0.0, 1.0);
    for (int block = blocks.begin(); block != blocks.end(); ++block) {
      const int last_row = std::min(height, (block + 1) * kRowsPerBlock);
      for (int v = block * kRowsPerBlock; v < last_row; ++v) {
        for (int u = 0; u < width; ++u) {
          const int i = v * width + u;
          const SurfaceSample& sample = rendered.pixels[i];
          // Surfaces closer than min_range are in the detector's blind zone: they hide what is behind but do
          // not return.
          if (!(sample.range_m >= min_range && sample.range_m <= max_range)) continue;
          const ardsim_description::Material& material = materialOf(sample);
          const bool retro = options_.retro_reflectors && material.retro_reflector &&
                             sample.cos_incidence >= cos_retro_acceptance_;
          if (options_.incidence_cutoff && !retro && sample.cos_incidence < cos_max_incidence_) continue;
          const double s =
              strength(material.reflectivity, sample.cos_incidence, material.retro_reflector, sample.range_m);
          CounterRng rng = streamOf(seed_, frame_index, Stream::kPixel, static_cast<std::uint64_t>(i));
          // Beyond s = 40 the probability is 1 to double precision: no draw needed (most close-range pixels).
          if (options_.return_probability && s < 40.0 && uniform01(rng) >= returnProbability(s)) continue;

          double range = sample.range_m;
          if (options_.mixed_pixels) {
            // The neighbour across the largest depth jump: the pixel's footprint straddles both surfaces.
            double jump = 0.0;
            const int neighbours[4][2] = {{u - 1, v}, {u + 1, v}, {u, v - 1}, {u, v + 1}};
            for (const auto& n : neighbours) {
              if (n[0] < 0 || n[0] >= width || n[1] < 0 || n[1] >= height) continue;
              const SurfaceSample& other = rendered.pixels[n[1] * width + n[0]];
              if (other.range_m <= 0.0f) continue;
              const double difference = other.range_m - sample.range_m;
              if (std::abs(difference) > std::abs(jump)) jump = difference;
            }
            if (std::abs(jump) > options_.mixed_pixel_min_jump_m &&
                uniform01(rng) < options_.mixed_pixel_probability)
              range += uniform01(rng) * jump;
          }
          if (options_.range_noise) range += rangeSigma(s) * normal(rng);
          const double return_intensity = intensity(s);
          const bool saturated = s >= saturation_strength_;
          if (options_.saturation && saturated) range += options_.saturation_range_bias_m;
          if (!(range >= min_range && range <= max_range)) continue;
          frame->range_m[i] = static_cast<float>(range);
          frame->intensity[i] = static_cast<float>(return_intensity);
          if (options_.blooming && retro && saturated) saturated_retro_pixels[block].push_back(i);
        }
      }
    }
  });

  // Blooming: light from a saturated retro-reflector spills into neighbours that have a weaker (or no)
  // return.
  const int radius = options_.bloom_radius_px;
  // In row order: where spills overlap, the result does not depend on threads.
  std::vector<int> bloom_sources;
  for (const auto& block : saturated_retro_pixels)
    bloom_sources.insert(bloom_sources.end(), block.begin(), block.end());
  for (const int source : bloom_sources) {
    CounterRng rng = streamOf(seed_, frame_index, Stream::kBloom, static_cast<std::uint64_t>(source));
    const int su = source % width;
    const int sv = source / width;
    for (int dv = -radius; dv <= radius; ++dv) {
      for (int du = -radius; du <= radius; ++du) {
        const int distance = std::max(std::abs(du), std::abs(dv));
        const int nu = su + du;
        const int nv = sv + dv;
        if (distance == 0 || nu < 0 || nu >= width || nv < 0 || nv >= height) continue;
        const double probability = options_.bloom_probability * (radius + 1 - distance) / radius;
        if (uniform01(rng) >= probability) continue;
        const int j = nv * width + nu;
        const float bloom_intensity = std::ldexp(1.0f, -distance);
        if (std::isnan(frame->intensity[j]) || frame->intensity[j] < bloom_intensity) {
          frame->range_m[j] = frame->range_m[source];
          frame->intensity[j] = bloom_intensity;
        }
      }
    }
  }

  CounterRng rng = streamOf(seed_, frame_index, Stream::kFrame, 0);
  // Background: rare and independent per pixel, so draw the gap to the next one (geometric) instead of a coin
  // per pixel. A spurious return comes before the true one (it triggers the detector first).
  if (options_.background_returns && options_.background_probability > 0.0) {
    std::geometric_distribution<int> gap(options_.background_probability);
    for (long i = gap(rng); i < pixel_count; i += 1 + static_cast<long>(gap(rng))) {
      const double upper = std::isnan(frame->range_m[i]) ? sensor_.max_range_m : frame->range_m[i];
      frame->range_m[i] =
          static_cast<float>(sensor_.min_range_m + uniform01(rng) * (upper - sensor_.min_range_m));
      frame->intensity[i] = static_cast<float>(uniform01(rng) * options_.background_intensity);
    }
  }
  for (int i = 0; i < pixel_count; ++i) {
    if (options_.hot_pixels && hot_[i]) {
      frame->range_m[i] = static_cast<float>(sensor_.min_range_m +
                                             uniform01(rng) * (sensor_.max_range_m - sensor_.min_range_m));
      frame->intensity[i] = static_cast<float>(uniform01(rng));
    }
    if (options_.dead_pixels && dead_[i]) {
      frame->range_m[i] = kNoReturn;
      frame->intensity[i] = kNoReturn;
    }
  }
}

}  // namespace ardsim_lidar
