// The real-scene benchmark (issue 16): the product's tracker on the ball composited onto
// opencv-doc's photographs and video (sim/real_scene.hpp), with the scored selection and with
// the paper's largest-region rule, in the same run.
//
//   build/bin/real_scene_bench [--frames 1440] [--selection both|scored|largest] [--no-adapt]
//
// Per scene and pooled: fully visible frames within 2 px of the true centre, missed, and on
// another object; the half-hidden ball's centre error (the tracker's centre and the centroid of
// eq. 11); false detections per 1,000 hidden frames; the tracker's median time per frame.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "system/real_scene_trial.hpp"

namespace {

using sg::system::quantile;
using sg::system::RealSceneFigures;

void print_row(const std::string& name, const RealSceneFigures& f) {
  std::printf(
      "%-13s %6d %6d %7.2f%% %5d %5d | %5d %6.2f %6.2f %6.2f %6.2f | %5d %5d %7.2f | %7.3f\n",
      name.c_str(), f.frames, f.visible, 100 * f.within_2px_share(), f.visible_missed,
      f.visible_elsewhere, f.half_hidden, quantile(f.half_centre_error, 0.5),
      quantile(f.half_centre_error, 0.95), quantile(f.half_centroid_error, 0.5),
      quantile(f.half_centroid_error, 0.95), f.hidden, f.hidden_false, f.false_per_1000_hidden(),
      quantile(f.seconds, 0.5) * 1e3);
}

void run(sg::vision::Selection selection, int frames, bool adapt) {
  std::printf("\nselection: %s, colour adaptation %s\n",
              selection == sg::vision::Selection::kScored ? "scored" : "largest",
              adapt ? "on" : "off");
  std::printf("%-13s %6s %6s %8s %5s %5s | %5s %6s %6s %6s %6s | %5s %5s %7s | %7s\n", "scene",
              "frames", "whole", "<=2px", "miss", "else", "half", "c p50", "c p95", "m p50",
              "m p95", "hid", "false", "/1000", "ms p50");
  RealSceneFigures all;
  for (const auto& scene : sg::sim::standard_real_scenes(frames)) {
    const RealSceneFigures f = sg::system::run_real_scene(scene, selection, adapt);
    print_row(scene.name, f);
    all.add(f);
  }
  print_row("pooled", all);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The product's ball tracker on real photographs and video (opencv-doc) with red "
      "distractors, lighting drift, noise, MJPG, occlusion; scored vs largest-region"};
  int frames = 1440;
  std::string selection = "both";
  app.add_option("--frames", frames, "frames per scene (720 a cycle)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  app.add_option("--selection", selection, "scored, largest or both")
      ->capture_default_str()
      ->check(CLI::IsMember({"both", "scored", "largest"}));
  bool no_adapt = false;
  app.add_flag("--no-adapt", no_adapt,
               "also the scored selection without colour adaptation (the configured ranges)");
  CLI11_PARSE(app, argc, argv);
  std::printf("real_scene_bench --frames %d --selection %s (data: %s)\n", frames, selection.c_str(),
              sg::sim::opencv_data_dir().c_str());
  std::printf(
      "c: the tracker's centre; m: the region's centroid (eq. 11); px. whole: fully "
      "visible frames; else: detection on another object\n");
  try {
    if (selection != "largest") run(sg::vision::Selection::kScored, frames, true);
    if (selection != "largest" && no_adapt) run(sg::vision::Selection::kScored, frames, false);
    if (selection != "scored") run(sg::vision::Selection::kLargest, frames, true);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "real_scene_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
