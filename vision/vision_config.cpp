#include "vision/vision_config.hpp"

namespace sg::vision {
namespace {

void range(const Config& c, const std::string& key, double& lo, double& hi) {
  if (!c.has(key)) return;
  const auto v = c.require<std::vector<double>>(key);
  if (v.size() != 2 || !(v[0] >= 0 && v[0] <= v[1] && v[1] <= 1))
    throw c.error_at(key, "must be [min, max] with 0 <= min <= max <= 1");
  lo = v[0], hi = v[1];
}

}  // namespace

BlobTracker::Params load_tracker_params(const Config& c) {
  BlobTracker::Params p;
  range(c, "vision.r_range", p.color.r_min, p.color.r_max);
  range(c, "vision.g_range", p.color.g_min, p.color.g_max);
  range(c, "vision.b_range", p.color.b_min, p.color.b_max);
  p.color.min_intensity = c.get<int>("vision.min_intensity", p.color.min_intensity);
  if (p.color.min_intensity < 0 || p.color.min_intensity > 765)
    throw c.error_at("vision.min_intensity", "must be between 0 and 765");
  p.min_area = c.get<int>("vision.min_area", p.min_area);
  if (p.min_area < 1) throw c.error_at("vision.min_area", "must be at least 1");
  p.min_area_fraction_of_last =
      c.get<double>("vision.min_area_fraction_of_last", p.min_area_fraction_of_last);
  if (!(p.min_area_fraction_of_last >= 0 && p.min_area_fraction_of_last <= 1))
    throw c.error_at("vision.min_area_fraction_of_last", "must be in [0, 1]");
  p.forget_size_after_misses =
      c.get<int>("vision.forget_size_after_misses", p.forget_size_after_misses);
  SearchWindowParams& w = p.window;
  w.diameter_factor = c.get<double>("vision.window_diameter_factor", w.diameter_factor);
  w.max_width_fraction = c.get<double>("vision.window_max_width", w.max_width_fraction);
  w.max_height_fraction = c.get<double>("vision.window_max_height", w.max_height_fraction);
  w.growth = c.get<double>("vision.window_growth", w.growth);
  w.misses_before_full_frame =
      c.get<int>("vision.misses_before_full_frame", w.misses_before_full_frame);
  if (!(w.diameter_factor > 0)) throw c.error_at("vision.window_diameter_factor", "must be > 0");
  if (!(w.max_width_fraction > 0 && w.max_width_fraction <= 1))
    throw c.error_at("vision.window_max_width", "must be in (0, 1]");
  if (!(w.max_height_fraction > 0 && w.max_height_fraction <= 1))
    throw c.error_at("vision.window_max_height", "must be in (0, 1]");
  if (!(w.growth >= 1)) throw c.error_at("vision.window_growth", "must be >= 1");
  return p;
}

}  // namespace sg::vision
