// The predictor's cost per sample: one update (Burg re-estimated on the window) plus the 16-step
// forecast, for one axis predictor and for the whole 3D trajectory predictor (three axes and the
// resampling), at p = 12 and W = 480; beside them, the Kalman baseline and a copy of the windows
// (the least an online re-estimation must touch) in the same run.
//
//   build/bin/predictor_bench
// Goal (issue 6): at most 20 microseconds per sample for Burg. Issue 19: the 3D sample at most
// 1.5 times one axis's (the three axes' Burg estimates in one pass, burg3).

#include <benchmark/benchmark.h>

#include <cmath>
#include <deque>

#include "bench/timing_reporter.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace {

using sg::predictor::Model;

Eigen::Vector3d paper(double t) {
  return {0.45 + 0.15 * std::cos(2 * M_PI * t / 60),
          0.15 * std::sin(2 * M_PI * t / 60) + 0.001 * std::sin(7 * t), 0.1};
}

void run(benchmark::State& state, Model model) {
  sg::predictor::PredictorParams p;
  p.model = model;
  p.burg.order = 12;
  p.burg.window = 480;
  sg::predictor::TrajectoryPredictor predictor(p);
  int64_t k = 0;
  for (; k < 600; ++k)
    predictor.add({1'000'000 + k * 250'000, true, paper(k * 0.25)});  // window full
  for (auto _ : state) {
    const auto f = predictor.add({1'000'000 + k * 250'000, true, paper(k * 0.25)});
    benchmark::DoNotOptimize(f.data());
    ++k;
  }
}

void BM_Sample_Burg(benchmark::State& state) { run(state, Model::kBurg); }
void BM_Sample_Kalman(benchmark::State& state) { run(state, Model::kKalman); }
BENCHMARK(BM_Sample_Burg)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly();
BENCHMARK(BM_Sample_Kalman)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly();

// One axis predictor alone: push a measured sample (Burg re-estimated on its window) and forecast
// 16 steps.
void BM_Axis_Burg(benchmark::State& state) {
  sg::predictor::BurgParams p;
  p.order = 12;
  p.window = 480;
  auto axis = sg::predictor::make_burg_axis(p);
  int64_t k = 0;
  for (; k < 600; ++k) axis->push(paper(k * 0.25).y(), true);
  for (auto _ : state) {
    axis->push(paper(k * 0.25).y(), true);
    const auto f = axis->forecast(16);
    benchmark::DoNotOptimize(f.data());
    ++k;
  }
}
BENCHMARK(BM_Axis_Burg)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly();

// Baseline: copying three windows of 480 samples.
void BM_Sample_CopyThreeWindows(benchmark::State& state) {
  std::deque<double> window(480, 1.0);
  std::vector<double> out(480);
  for (auto _ : state) {
    for (int axis = 0; axis < 3; ++axis) std::copy(window.begin(), window.end(), out.begin());
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_Sample_CopyThreeWindows)
    ->Unit(benchmark::kMicrosecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly();

}  // namespace

int main(int argc, char** argv) {
  return sg::bench::run_benchmarks(argc, argv, [](const sg::bench::TimingReporter& r) {
    const double axis = r.time("BM_Axis_Burg"), sample = r.time("BM_Sample_Burg");
    std::printf("\nper sample (median)          time       goal\n");
    std::printf("  one Burg axis          %8.2f us\n", axis);
    std::printf("  the 3D sample (Burg)   %8.2f us    <= 20 us; %.2fx one axis (<= 1.5x)\n", sample,
                sample / axis);
    std::printf("  the 3D sample (Kalman) %8.2f us\n", r.time("BM_Sample_Kalman"));
    std::printf("  copy three windows     %8.2f us\n", r.time("BM_Sample_CopyThreeWindows"));
  });
}
