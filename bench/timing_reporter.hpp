#pragma once

#include <benchmark/benchmark.h>

#include <functional>
#include <map>
#include <string>

namespace sg::bench {

/// Prints Google Benchmark's usual table and keeps each benchmark's real time per iteration (the
/// median when it is repeated), so a program can print ratios against a baseline of the same run.
class TimingReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      const bool single = run.run_type == Run::RT_Iteration && run.repetitions <= 1;
      if (single || run.aggregate_name == "median")
        times_[run.run_name.function_name] = run.GetAdjustedRealTime();
    }
    ConsoleReporter::ReportRuns(runs);
  }
  /// Time per iteration in the benchmark's unit; throws std::out_of_range for an unknown name.
  double time(const std::string& name) const { return times_.at(name); }
  const std::map<std::string, double>& times() const { return times_; }

 private:
  std::map<std::string, double> times_;
};

/// Runs the benchmarks given on the command line, then `after` with what was measured.
inline int run_benchmarks(int argc, char** argv,
                          const std::function<void(const TimingReporter&)>& after) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  TimingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  after(reporter);
  benchmark::Shutdown();
  return 0;
}

}  // namespace sg::bench
