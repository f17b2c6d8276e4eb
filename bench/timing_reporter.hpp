#pragma once

#include <benchmark/benchmark.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

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
  /// Whether `name` ran (a --benchmark_filter may have left it out).
  bool has(const std::string& name) const { return times_.count(name) != 0; }
  const std::map<std::string, double>& times() const { return times_; }

 private:
  std::map<std::string, double> times_;
};

/// Runs the benchmarks given on the command line, then `after` with what was measured.
/// `defaults`: flags as if given first on the command line (the user's own come after and win).
inline int run_benchmarks(int argc, char** argv,
                          const std::function<void(const TimingReporter&)>& after,
                          const std::vector<std::string>& defaults = {}) {
  std::vector<std::string> flags(defaults);
  std::vector<char*> args{argv[0]};
  for (std::string& f : flags) args.push_back(f.data());
  args.insert(args.end(), argv + 1, argv + argc);
  args.push_back(nullptr);
  argc = static_cast<int>(args.size()) - 1, argv = args.data();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  TimingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  after(reporter);
  benchmark::Shutdown();
  return 0;
}

}  // namespace sg::bench
