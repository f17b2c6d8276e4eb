#pragma once

/// The product's per-camera tracker (vision::BlobTracker, as sg-vision runs it) on real-scene
/// frames (sim/real_scene.hpp), scored against the frames' truth: the figures of the real-scene
/// benchmark (bench/real_scene_bench) and test (tests/system/real_scene_trial_test.cpp).
///
///     const RealSceneFigures f = run_real_scene(scene_params, vision::Selection::kScored);
///     std::printf("%.2f%% within 2 px\n", 100 * f.within_2px_share());
///
/// A frame is fully visible when at least 99% of the ball's disc is, half hidden when 40-60% is,
/// hidden when none is. A detection lies on another object when its centre is farther than the
/// ball's radius from the ball's true centre.

#include <cstdint>
#include <vector>

#include "sim/real_scene.hpp"
#include "vision/blob_tracker.hpp"

namespace sg::system {

struct RealSceneFigures {
  int frames = 0;
  int visible = 0;  ///< fully visible frames
  int visible_within_2px = 0;
  int visible_missed = 0;
  int visible_elsewhere = 0;  ///< ... where the detection lay on another object
  int half_hidden = 0;
  std::vector<double> half_centre_error;  ///< px, Observation::centre, per half-hidden frame found
  std::vector<double> half_centroid_error;  ///< px, the region's centroid (eq. 11), same frames
  int hidden = 0;
  int hidden_false = 0;         ///< hidden frames with a detection
  std::vector<double> seconds;  ///< the tracker's time per frame

  double within_2px_share() const { return visible ? visible_within_2px / double(visible) : 0; }
  double false_per_1000_hidden() const { return hidden ? 1000.0 * hidden_false / hidden : 0; }
  void add(const RealSceneFigures& other);
};

/// Runs the tracker with `selection` and colour adaptation on or off (other parameters the
/// defaults sg-vision starts from) over every frame of the scene.
RealSceneFigures run_real_scene(const sim::RealSceneParams& scene, vision::Selection selection,
                                bool adapt_colour = true);

/// The q-quantile (0..1) of `v` by nearest rank; NaN when empty.
double quantile(std::vector<double> v, double q);

}  // namespace sg::system
