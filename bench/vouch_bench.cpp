// What vouching costs a message (docs/security.md, "Every datum vouched for"): the publisher's
// DataGuard::vouch and the reader's DataGuard::check of the same bytes, each pair timed alone, N
// times, for sg-predictor's forecast (trajectory_t, 16 points, under 1 KB; two readers), a
// PROCESS_STATUS (every identity a reader: the most tags a message carries) and a 640x480 JPEG
// stereo pair of the simulated lab (each image vouched for sg-vision and sg-viewer and checked by
// sg-vision). Beside them, in the same run, the baselines: LCM's encode and sg::safe_decode of the
// same message (what every publish and receive does anyway) and a signed command's sign + verify
// (HMAC-SHA-512-256). Prints p50 and p99 in us, and each p50 over its baseline's.
//
//   build/bin/vouch_bench [--n 20000]
//   goals: a message under 1 KB, vouch + check <= 50 us at p99; a JPEG pair <= 0.3 ms at p99

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "auth/command_auth.hpp"
#include "auth/data_auth.hpp"
#include "common/safe_decode.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/image_message.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using sg::auth::DataGuard;

sg::auth::LabKey bench_key() {
  std::array<uint8_t, sg::auth::LabKey::kSize> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(31 * i + 7);
  return sg::auth::LabKey(bytes);
}

struct Percentiles {
  double p50 = 0, p99 = 0;
};

/// Runs `op` n times, each timed alone; p50 and p99 in us.
Percentiles time_each(int n, const std::function<void()>& op) {
  std::vector<double> us(static_cast<std::size_t>(n));
  for (int i = 0; i < 200; ++i) op();  // warm caches and tables
  for (double& t : us) {
    const auto a = Clock::now();
    op();
    t = std::chrono::duration<double, std::micro>(Clock::now() - a).count();
  }
  std::sort(us.begin(), us.end());
  return {us[us.size() / 2], us[static_cast<std::size_t>(0.99 * static_cast<double>(us.size()))]};
}

template <class M>
std::vector<uint8_t> encode(const M& m) {
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

stereograsp::trajectory_t forecast() {
  stereograsp::trajectory_t t{};
  t.utime = t.source_utime = sg::now_utime();
  t.period_us = 250'000;
  t.num_points = 16;
  t.position.assign(16, {0.45, 0.1, 0.1});
  t.position_sigma.assign(16, {0.001, 0.001, 0.001});
  t.status = stereograsp::trajectory_t::STATUS_TRACKING;
  return t;
}

stereograsp::process_status_t status() {
  stereograsp::process_status_t s{};
  s.process = "sg-predictor";
  s.host = "lab2";
  s.num_channels = 3;
  s.channel = {"OBJECT_POSITION", "OBJECT_TRAJECTORY", "PROCESS_STATUS"};
  s.messages_in = s.messages_out = {100, 100, 100};
  s.rate_in_hz = s.rate_out_hz = {30, 4, 1};
  s.num_peers = 5;
  for (int i = 0; i < 5; ++i) s.peer.push_back("sg-vision@lab1:" + std::to_string(1000 + i));
  s.peer_utime = s.peer_recv_utime = s.peer_offset_us = s.peer_offset_error_us =
      std::vector<int64_t>(5, 1);
  return s;
}

/// The publisher vouches `channel`'s message as `from`; `to` checks it (accepted each time).
Percentiles vouch_and_check(int n, const std::string& channel, const std::vector<uint8_t>& message,
                            const std::string& from, const std::string& to) {
  DataGuard sender(sg::auth::credentials_from_lab_key(bench_key(), from));
  DataGuard reader(sg::auth::credentials_from_lab_key(bench_key(), to));
  std::vector<uint8_t> bytes;
  bytes.reserve(message.size() + 2048);
  return time_each(n, [&] {
    bytes.assign(message.begin(), message.end());
    sender.vouch(channel, bytes);
    const sg::GuardResult r = reader.check(channel, bytes.data(), bytes.size(), sg::now_utime());
    if (!r.accepted()) throw std::runtime_error("vouch_bench: refused: " + r.reason);
  });
}

/// LCM's encode and sg::safe_decode of `m` into `out`, through `bytes`: what every publish and
/// receive does anyway, without vouching.
template <class M>
void round_trip(const M& m, std::vector<uint8_t>& bytes, M& out) {
  bytes.resize(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (!sg::safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), out))
    throw std::runtime_error("vouch_bench: the baseline did not decode");
}

/// The baseline of one message: its round trip.
template <class M>
Percentiles encode_and_decode(int n, const M& m) {
  std::vector<uint8_t> bytes;
  M out{};
  return time_each(n, [&] { round_trip(m, bytes, out); });
}

/// A 640x480 JPEG pair of the simulated lab, as sg-camera-sim publishes it.
std::array<stereograsp::image_t, 2> jpeg_pair() {
  const sg::sim::SimParams params;
  sg::sim::CameraSimulator sim(params);
  sg::sim::StereoFrame f;
  sim.render(10, {}, f);
  std::array<stereograsp::image_t, 2> pair;
  for (std::size_t i = 0; i < 2; ++i)
    pair[i] = sg::vision::encode_image(f.image[i], static_cast<int8_t>(i), 10, 333330, true);
  return pair;
}

void row(const char* what, std::size_t bytes, Percentiles p, Percentiles base) {
  std::printf("%-44s %7zu B  p50 %8.2f us  p99 %8.2f us  p50 %6.2fx its baseline\n", what, bytes,
              p.p50, p.p99, p.p50 / base.p50);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"What vouching for a message costs its publisher and its reader (p50, p99).",
               "vouch_bench"};
  int n = 20000;
  app.add_option("--n", n, "operations timed per case")->check(CLI::Range(100, 10'000'000));
  CLI11_PARSE(app, argc, argv);

  const std::vector<uint8_t> t = encode(forecast()), s = encode(status());
  const auto pair = jpeg_pair();
  const std::vector<uint8_t> left = encode(pair[0]), right = encode(pair[1]);

  const Percentiles t_base = encode_and_decode(n, forecast());
  const Percentiles t_vouch =
      vouch_and_check(n, "OBJECT_TRAJECTORY", t, "sg-predictor", "sg-grasp");
  const Percentiles s_base = encode_and_decode(n, status());
  const Percentiles s_vouch = vouch_and_check(n, "PROCESS_STATUS", s, "sg-predictor", "sg-grasp");
  const int images = std::max(100, n / 20);
  std::vector<uint8_t> scratch;
  stereograsp::image_t decoded{};
  const Percentiles j_base = time_each(images, [&] {
    round_trip(pair[0], scratch, decoded);
    round_trip(pair[1], scratch, decoded);
  });
  DataGuard camera(sg::auth::credentials_from_lab_key(bench_key(), "sg-camera-sim"));
  DataGuard vision(sg::auth::credentials_from_lab_key(bench_key(), "sg-vision"));
  std::vector<uint8_t> a, b;
  const Percentiles j_vouch = time_each(images, [&] {
    a.assign(left.begin(), left.end());
    b.assign(right.begin(), right.end());
    camera.vouch("CAMERA_LEFT", a);
    camera.vouch("CAMERA_RIGHT", b);
    const int64_t now = sg::now_utime();
    if (!vision.check("CAMERA_LEFT", a.data(), a.size(), now).accepted() ||
        !vision.check("CAMERA_RIGHT", b.data(), b.size(), now).accepted())
      throw std::runtime_error("vouch_bench: an image was refused");
  });
  sg::auth::CommandSigner signer(bench_key(), "sg-grasp");
  sg::auth::CommandVerifier verifier(bench_key());
  stereograsp::arm_cmd_t command{};
  command.mode = stereograsp::arm_cmd_t::MODE_CARTESIAN;
  const Percentiles c = time_each(n, [&] {
    ++command.sequence;
    signer.sign("ARM_COMMAND", command);
    if (!verifier.verify("ARM_COMMAND", command, command.auth_counter).accepted())
      throw std::runtime_error("vouch_bench: a signed command was refused");
  });

  std::printf("%d operations a case (images: %d pairs); each timed alone\n\n", n, images);
  row("trajectory_t: encode + safe_decode (baseline)", t.size(), t_base, t_base);
  row("trajectory_t: vouch (2 readers) + check", t.size(), t_vouch, t_base);
  row("process_status_t: encode + safe_decode", s.size(), s_base, s_base);
  row("process_status_t: vouch (12 readers) + check", s.size(), s_vouch, s_base);
  row("JPEG pair: encode + safe_decode", left.size() + right.size(), j_base, j_base);
  row("JPEG pair: vouch + check, both images", left.size() + right.size(), j_vouch, j_base);
  row("arm_cmd_t: sign + verify (HMAC)", encode(command).size(), c, c);
  const double small = std::max(t_vouch.p99, s_vouch.p99);
  std::printf("\nunder 1 KB, vouch + check p99: %.2f us (goal <= 50 us) %s\n", small,
              small <= 50 ? "ok" : "OVER");
  std::printf("JPEG pair, vouch + check p99: %.1f us (goal <= 300 us) %s\n", j_vouch.p99,
              j_vouch.p99 <= 300 ? "ok" : "OVER");
  return 0;
}
