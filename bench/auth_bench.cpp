// What signing costs a command (issue 15's figure: signing + checking <= 20 µs a command): one
// arm_cmd_t signed by CommandSigner and checked by CommandVerifier (HMAC-SHA-512-256, libsodium),
// each alone and together, and the refusal of a forged one. Repeated 9 times; prints the table,
// then the median of sign + verify in µs (docs/security.md).
//
//   build/bin/auth_bench [--benchmark_filter=SignAndVerify]

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "auth/command_auth.hpp"
#include "bench/timing_reporter.hpp"
#include "common/clock.hpp"

namespace {

using stereograsp::arm_cmd_t;

sg::auth::LabKey bench_key() {
  std::array<uint8_t, sg::auth::LabKey::kSize> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(31 * i + 7);
  return sg::auth::LabKey(bytes);
}

/// sg-grasp's kind of command: a Cartesian move with its times.
arm_cmd_t bench_command() {
  arm_cmd_t c{};
  c.utime = sg::now_utime();
  c.source_utime = c.utime - 40'000;
  c.target_utime = c.utime + 800'000;
  c.sequence = 1;
  c.mode = arm_cmd_t::MODE_CARTESIAN;
  c.position[0] = 0.45, c.position[1] = 0.10, c.position[2] = 0.30;
  c.orientation[0] = std::numbers::pi;
  c.gripper = arm_cmd_t::GRIPPER_KEEP;
  c.speed = 0.5;
  return c;
}

// Sign one command (sender, counter, tag) and check it as the driver does (accepted).
void BM_ArmCommand_SignAndVerify(benchmark::State& state) {
  const sg::auth::LabKey key = bench_key();
  sg::auth::CommandSigner signer(key, "sg-grasp");
  sg::auth::CommandVerifier verifier(key);
  arm_cmd_t c = bench_command();
  for (auto _ : state) {
    ++c.sequence;
    signer.sign("ARM_COMMAND", c);
    const sg::auth::Verification v = verifier.verify("ARM_COMMAND", c, c.auth_counter);
    if (!v.accepted()) state.SkipWithError(v.reason.c_str());
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(BM_ArmCommand_SignAndVerify)
    ->Unit(benchmark::kMicrosecond)
    ->Repetitions(9)
    ->ReportAggregatesOnly(true);

// Sign alone.
void BM_ArmCommand_Sign(benchmark::State& state) {
  sg::auth::CommandSigner signer(bench_key(), "sg-grasp");
  arm_cmd_t c = bench_command();
  for (auto _ : state) {
    signer.sign("ARM_COMMAND", c);
    benchmark::DoNotOptimize(c.auth_tag);
  }
}
BENCHMARK(BM_ArmCommand_Sign)->Unit(benchmark::kMicrosecond);

// Refuse a forged command (a random-looking tag): the whole check runs, nothing is remembered.
void BM_ArmCommand_RefuseForged(benchmark::State& state) {
  sg::auth::CommandVerifier verifier(bench_key());
  arm_cmd_t c = bench_command();
  c.sender = "sg-grasp";
  c.auth_counter = c.utime;
  for (std::size_t i = 0; i < sg::auth::kTagSize; ++i) c.auth_tag[i] = static_cast<uint8_t>(i + 1);
  for (auto _ : state) {
    const sg::auth::Verification v = verifier.verify("ARM_COMMAND", c, c.utime);
    if (v.verdict != sg::auth::Verdict::kBadTag) state.SkipWithError("a forged tag was accepted");
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(BM_ArmCommand_RefuseForged)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  return sg::bench::run_benchmarks(argc, argv, [](const sg::bench::TimingReporter& r) {
    const auto it = r.times().find("BM_ArmCommand_SignAndVerify");
    if (it == r.times().end()) return;
    std::printf("\nsign + verify of one arm_cmd_t: median %.2f us (issue 15: <= 20 us) %s\n",
                it->second, it->second <= 20.0 ? "ok" : "OVER");
  });
}
