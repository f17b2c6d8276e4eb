// How fast the camera simulator renders 640x480 stereo pairs on one core, against copying the two
// static backgrounds into two frames (the least any renderer must do) in the same run.
//
//   build/bin/sim_bench
// Goal (issue 3): at least 200 stereo pairs per second.

#include <benchmark/benchmark.h>

#include "sim/camera_simulator.hpp"

namespace {

sg::sim::SimParams params_with(bool gripper_and_occluder) {
  sg::sim::SimParams p;
  if (gripper_and_occluder) p.occlusion.episodes = {{0.0, 1e9}};
  return p;
}

// Baseline: two 640x480 BGR copies.
void BM_Pair_CopyBaseline(benchmark::State& state) {
  sg::sim::CameraSimulator sim(sg::sim::SimParams{});
  cv::Mat left, right;
  for (auto _ : state) {
    sim.renderer(0).background().copyTo(left);
    sim.renderer(1).background().copyTo(right);
    benchmark::DoNotOptimize(left.data);
  }
  state.counters["pairs_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Pair_CopyBaseline)->Unit(benchmark::kMicrosecond);

// The paper's scenario: ball, lighting changes, noise.
void BM_Pair_Render(benchmark::State& state) {
  sg::sim::CameraSimulator sim(params_with(false));
  sg::sim::StereoFrame frame;
  int64_t k = 0;
  for (auto _ : state) sim.render(k++, {}, frame);
  state.counters["pairs_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Pair_Render)->Unit(benchmark::kMicrosecond);

// The busiest frame: the gripper over the ball and the occluder in front.
void BM_Pair_RenderWithGripperAndOccluder(benchmark::State& state) {
  sg::sim::CameraSimulator sim(params_with(true));
  sg::sim::ArmState arm;
  arm.present = true;
  arm.tool_rpy = {0, M_PI, 0};
  sg::sim::StereoFrame frame;
  int64_t k = 0;
  for (auto _ : state) {
    arm.tool_position = sim.ball_position(k, {}) + Eigen::Vector3d(0, 0, 0.05);
    sim.render(k++, arm, frame);
  }
  state.counters["pairs_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Pair_RenderWithGripperAndOccluder)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
