#include "vision/vision_config.hpp"

namespace sg::vision {
namespace {

/// [min, max] of one normalized colour band.
void band(Section& c, const std::string& key, double& lo, double& hi, const std::string& help) {
  double v[2] = {lo, hi};
  c.numbers(key, v, 2, Range::closed(0, 1), help);
  if (!(v[0] <= v[1])) throw c.error(key, "must be [min, max] with min <= max");
  lo = v[0], hi = v[1];
}

}  // namespace

VisionSettings read_vision_settings(const Config& config) {
  VisionSettings s;
  BlobTracker::Params& p = s.tracker;
  ColorThresholds& k = p.color;
  SearchWindowParams& w = p.window;
  Section c(config, "vision");
  c.text("calibration", s.calibration, "stereo calibration file (then OBJECT_POSITION too)");
  c.choice("decode", s.decode, {"region", "full"},
           "JPEGs: decode only the search windows while tracking (region), or whole (full)");
  c.choice("camera_read", s.camera_read, {"direct", "lcm"},
           "udpm: read the camera channels on our own socket (direct) or through LCM (lcm)");
  c.number("realtime_priority", s.realtime_priority, Range::closed(0, 99),
           "SCHED_FIFO priority with memory locked (needs CAP_SYS_NICE; 0: off)");
  c.number("busy_wait_ms", s.busy_wait_ms, Range::closed(0, 50),
           "ms either side of when a pair is due that the decode workers poll (0: never)");
  band(c, "r_range", k.r_min, k.r_max, "normalized r = R/(R+G+B) of the ball (eq. 7)");
  band(c, "g_range", k.g_min, k.g_max, "normalized g of the ball");
  band(c, "b_range", k.b_min, k.b_max, "normalized b of the ball");
  c.number("min_intensity", k.min_intensity, Range::closed(0, 765),
           "R+G+B below this is too dark to have a colour");
  c.number("min_area", p.min_area, Range::closed(1, 1e8), "px: smaller regions are ignored");
  c.number("min_area_fraction_of_last", p.min_area_fraction_of_last, Range::closed(0, 1),
           "while tracking, a region must be this much of the ball's last area");
  c.number("forget_size_after_misses", p.forget_size_after_misses, Range::closed(0, 1e6),
           "... until the ball has been missing this many frames");
  c.number("window_diameter_factor", w.diameter_factor, Range::above_to(0, 100),
           "search window side = this x the apparent diameter");
  c.number("window_max_width", w.max_width_fraction, Range::above_to(0, 1),
           "at most this fraction of the image width ...");
  c.number("window_max_height", w.max_height_fraction, Range::above_to(0, 1),
           "... and of its height");
  c.number("window_growth", w.growth, Range::closed(1, 100), "the window grows by this per miss");
  c.number("misses_before_full_frame", w.misses_before_full_frame, Range::closed(0, 1e6),
           "misses before the whole image is searched");
  std::string selection = p.selection == Selection::kLargest ? "largest" : "scored";
  c.choice("selection", selection, {"scored", "largest"},
           "which region is the ball: scored (shape, size, colour, track, stereo) or the paper's "
           "largest region");
  p.selection = selection == "largest" ? Selection::kLargest : Selection::kScored;
  c.number("ball_radius", s.match.ball_radius, Range::closed(0, 10),
           "m: the ball's radius, for its size at its depth (0: unknown)");
  c.number("epipolar_sigma", s.match.epipolar_sigma, Range::above_to(0, 1000),
           "px: reprojection error of a true stereo pair");
  c.number("max_cost", p.scoring.max_cost, Range::above_to(0, 1e6),
           "a region scoring worse than this is not the ball");
  c.number("acquire_max_cost", p.scoring.acquire_max_cost, Range::above_to(0, 1e6),
           "... and worse than this starts no track (none yet, or the last frame missed)");
  c.number("acquire_min_support", p.scoring.acquire_min_support, Range::closed(0, 1),
           "... nor a region with less of a circle in its outline (a whole disc: 1)");
  ColorAdaptationParams& a = p.adaptation;
  c.flag("adapt_color", a.enabled,
         "narrow the colour ranges to the ball's as it is seen, within the ranges above");
  c.number("adapt_margin", a.margin, Range::closed(0, 1),
           "added on each side of the ball's learned ranges");
  c.number("adapt_min_width", a.min_width, Range::closed(0, 1),
           "a learned range is never narrower than this");
  c.done();
  return s;
}

}  // namespace sg::vision
