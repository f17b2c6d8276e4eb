// What the bus costs a process: encoding and decoding stereograsp messages, and a typed
// publish-subscribe round through sg::Bus, against copying the same bytes (the baseline).
// Prints Google Benchmark's table, then each case as a ratio to its baseline from the same run.
//
//   build/bin/lcmtypes_bench [--benchmark_filter=Image]

#include <benchmark/benchmark.h>

#include <cstring>
#include <map>

#include "bench/timing_reporter.hpp"
#include "common/bus.hpp"
#include "common/message_types.hpp"

namespace {

using namespace stereograsp;

image_t make_image() {
  image_t image{};
  image.width = 640;
  image.height = 480;
  image.row_stride = 640 * 3;
  image.pixel_format = image_t::FORMAT_BGR8;
  image.size = image.row_stride * image.height;
  image.data.assign(static_cast<size_t>(image.size), 0x5a);
  return image;
}

trajectory_t make_trajectory() {
  trajectory_t t{};
  t.num_points = 16;
  t.position.assign(16, std::vector<double>{0.5, 0.1, 0.2});
  t.position_sigma.assign(16, std::vector<double>{0.001, 0.001, 0.001});
  return t;
}

// Baseline: copy a 640x480 BGR frame's bytes.
void BM_Image_CopyBaseline(benchmark::State& state) {
  const image_t image = make_image();
  std::vector<uint8_t> out(image.data.size());
  for (auto _ : state) {
    std::memcpy(out.data(), image.data.data(), out.size());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(out.size()));
}
BENCHMARK(BM_Image_CopyBaseline);

void BM_Image_Encode(benchmark::State& state) {
  const image_t image = make_image();
  std::vector<uint8_t> out(static_cast<size_t>(image.getEncodedSize()));
  for (auto _ : state) {
    image.encode(out.data(), 0, static_cast<int>(out.size()));
    benchmark::DoNotOptimize(out.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(out.size()));
}
BENCHMARK(BM_Image_Encode);

void BM_Image_Decode(benchmark::State& state) {
  const std::vector<uint8_t> bytes = sg::encode_message(make_image());
  image_t image{};
  for (auto _ : state) {
    image.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
    benchmark::DoNotOptimize(image.data.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(BM_Image_Decode);

// Baseline: copy a 16-point trajectory's 384 bytes of coordinates.
void BM_Trajectory_CopyBaseline(benchmark::State& state) {
  double from[16][3] = {};
  double to[16][3];
  for (auto _ : state) {
    std::memcpy(to, from, sizeof to);
    benchmark::DoNotOptimize(to);
  }
}
BENCHMARK(BM_Trajectory_CopyBaseline);

void BM_Trajectory_EncodeDecode(benchmark::State& state) {
  const trajectory_t t = make_trajectory();
  std::vector<uint8_t> bytes(static_cast<size_t>(t.getEncodedSize()));
  trajectory_t back{};
  for (auto _ : state) {
    t.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    back.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
    benchmark::DoNotOptimize(back.position.data());
  }
}
BENCHMARK(BM_Trajectory_EncodeDecode);

// A typed publish and its delivery to a typed subscriber, in process (memq://).
void BM_Trajectory_BusRoundMemq(benchmark::State& state) {
  sg::Bus bus("memq://");
  int64_t received = 0;
  bus.subscribe<trajectory_t>("OBJECT_TRAJECTORY",
                              [&](const trajectory_t&, const sg::ReceiveInfo&) { ++received; });
  const trajectory_t t = make_trajectory();
  for (auto _ : state) {
    bus.publish("OBJECT_TRAJECTORY", t);
    bus.handle(std::chrono::milliseconds(100));
  }
  if (received != state.iterations()) state.SkipWithError("a message was lost");
}
BENCHMARK(BM_Trajectory_BusRoundMemq);

}  // namespace

// After the table: each case as a ratio to its group's CopyBaseline (BM_<Group>_...).
int main(int argc, char** argv) {
  return sg::bench::run_benchmarks(argc, argv, [](const sg::bench::TimingReporter& r) {
    std::printf("\nratio to baseline (same run; lower is cheaper):\n");
    for (const auto& [name, ns] : r.times()) {
      const std::string group = name.substr(0, name.find('_', 3) + 1);
      const auto base = r.times().find(group + "CopyBaseline");
      if (base == r.times().end() || base->first == name) continue;
      std::printf("  %-32s %10.1f ns  %6.2fx %s\n", name.c_str(), ns, ns / base->second,
                  base->first.c_str());
    }
  });
}
