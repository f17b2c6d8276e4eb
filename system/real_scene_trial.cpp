#include "system/real_scene_trial.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace sg::system {
namespace {

void score(const sim::RealSceneTruth& t, const vision::Observation& o, RealSceneFigures& f) {
  const double error = o.found ? std::hypot(o.centre.x - t.centre.x, o.centre.y - t.centre.y) : 0;
  if (t.visible >= 0.99) {
    ++f.visible;
    if (!o.found) {
      ++f.visible_missed;
    } else if (error > t.radius) {
      ++f.visible_elsewhere;
    } else if (error <= 2.0) {
      ++f.visible_within_2px;
    }
  } else if (t.visible >= 0.4 && t.visible <= 0.6) {
    ++f.half_hidden;
    if (o.found) {
      f.half_centre_error.push_back(error);
      f.half_centroid_error.push_back(
          std::hypot(o.blob.centroid.x - t.centre.x, o.blob.centroid.y - t.centre.y));
    }
  } else if (t.visible == 0) {
    ++f.hidden;
    f.hidden_false += o.found ? 1 : 0;
  }
}

}  // namespace

void RealSceneFigures::add(const RealSceneFigures& o) {
  frames += o.frames, visible += o.visible, visible_within_2px += o.visible_within_2px;
  visible_missed += o.visible_missed, visible_elsewhere += o.visible_elsewhere;
  half_hidden += o.half_hidden, hidden += o.hidden, hidden_false += o.hidden_false;
  half_centre_error.insert(half_centre_error.end(), o.half_centre_error.begin(),
                           o.half_centre_error.end());
  half_centroid_error.insert(half_centroid_error.end(), o.half_centroid_error.begin(),
                             o.half_centroid_error.end());
  seconds.insert(seconds.end(), o.seconds.begin(), o.seconds.end());
}

RealSceneFigures run_real_scene(const sim::RealSceneParams& scene, vision::Selection selection,
                                bool adapt_colour) {
  sim::RealScene generator(scene);
  vision::BlobTracker::Params params;
  params.selection = selection;
  params.adaptation.enabled = adapt_colour;
  vision::BlobTracker tracker(params, {640, 480});
  RealSceneFigures f;
  cv::Mat bgr;
  sim::RealSceneTruth truth;
  for (int k = 0; k < scene.frames; ++k) {
    generator.render(k, bgr, truth);
    const auto start = std::chrono::steady_clock::now();
    const vision::Observation o = tracker.track(bgr);
    f.seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    ++f.frames;
    score(truth, o, f);
  }
  return f;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const auto i = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, i == 0 ? 0 : i - 1)];
}

}  // namespace sg::system
