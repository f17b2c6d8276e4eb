// sg-report as a process: on a synthetic log with known contents (and damage), and on a session
// recorded live by the real lcm-logger from the real sg-predictor fed by this test (UDP port
// 7922): report.json's figures, report.md, the CSVs, `export`, `channels`, and exit codes.

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

/// Events per channel in an lcm-logger file, read with LCM's own reader.
std::map<std::string, int> events_per_channel(const std::string& path) {
  lcm::LogFile file(path, "r");
  std::map<std::string, int> count;
  if (!file.good()) return count;
  while (const lcm::LogEvent* e = file.readNextEvent()) ++count[e->channel];
  return count;
}

using namespace std::chrono_literals;
using Json = nlohmann::json;
namespace fs = std::filesystem;

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr int kPositions = 300;  // 10 s at 30 Hz

void write_event(lcm::LogFile& log, const std::string& channel, int64_t recv,
                 std::vector<uint8_t> bytes) {
  lcm::LogEvent e;
  e.eventnum = 0;
  e.timestamp = recv;
  e.channel = channel;
  e.datalen = static_cast<int32_t>(bytes.size());
  e.data = bytes.data();
  log.writeEvent(&e);
}

/// 300 OBJECT_POSITION at 30 Hz received 5 ms late, 40 trajectories, 5 messages on an unknown
/// channel, and 37 bytes of garbage after the 100th position.
std::string synthetic_log(const std::string& dir) {
  const std::string path = dir + "/synthetic.lcmlog";
  lcm::LogFile log(path, "w");
  int trajectory = 0;
  for (int k = 0; k < kPositions; ++k) {
    const int64_t u = kT0 + (static_cast<int64_t>(k) * 1'000'000 + 15) / 30;
    stereograsp::point3_t p{};
    p.utime = u;
    p.visible = true;
    p.position[0] = 0.5 + 0.1 * std::cos(k / 30.0);
    p.position[1] = 0.1 * std::sin(k / 30.0);
    p.reprojection_error = 0.4;
    write_event(log, "OBJECT_POSITION", u + 5000, encode_message(p));
    if (k == 100) std::fwrite("0123456789012345678901234567890123456", 1, 37, log.getFilePtr());
    if (k % 5 == 0) write_event(log, "MYSTERY", u + 100, {9, 8, 7, 6, 5, 4, 3, 2, 1});
    while (trajectory < 40 && kT0 + trajectory * 250'000 <= u) {
      stereograsp::trajectory_t t{};
      t.utime = kT0 + trajectory * 250'000;
      t.source_utime = u;  // the position that triggered it
      t.period_us = 250'000;
      t.start_utime = t.utime + t.period_us;
      t.num_points = 16;
      t.position.assign(16, std::vector<double>{0.5, 0, 0.2});
      t.position_sigma.assign(16, std::vector<double>{0.001, 0.001, 0.001});
      t.status = 1;
      write_event(log, "OBJECT_TRAJECTORY", u + 8000, encode_message(t));
      ++trajectory;
    }
  }
  return path;
}

Json read_json(const std::string& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

const Json* find_channel(const Json& report, const std::string& name) {
  for (const Json& c : report["channels"])
    if (c["name"] == name) return &c;
  return nullptr;
}

class ReportProcess : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = make_temp_dir();
    log_ = synthetic_log(dir_);
  }
  static std::string dir_, log_;
};
std::string ReportProcess::dir_, ReportProcess::log_;

// The report of a known log: the figures in report.json, report.md, a CSV per channel, plots.
TEST_F(ReportProcess, ReportOfASyntheticLog) {
  const ProcessResult r = run({program("sg-report"), log_}, 60s);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::string out_dir = dir_ + "/synthetic.report";  // the default: LOG without .lcmlog
  EXPECT_NE(r.out.find(out_dir + "/report.md"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("37 bytes skipped"), std::string::npos) << r.out;
  const Json j = read_json(out_dir + "/report.json");
  EXPECT_EQ(j["log"]["events"], kPositions + 40 + kPositions / 5);
  ASSERT_EQ(j["log"]["problems"].size(), 1u);
  EXPECT_EQ(j["log"]["problems"][0]["bytes"], 37);
  const Json* pos = find_channel(j, "OBJECT_POSITION");
  ASSERT_NE(pos, nullptr);
  EXPECT_EQ((*pos)["count"], kPositions);
  EXPECT_EQ((*pos)["type"], "point3_t");
  EXPECT_NEAR((*pos)["rate_hz"].get<double>(), 30.0, 1e-3);
  EXPECT_NEAR(j["latency_ms"]["OBJECT_POSITION"]["p50"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(j["latency_ms"]["OBJECT_TRAJECTORY"]["p99"].get<double>(), 8.0, 1e-9);
  ASSERT_EQ(j["unknown_channels"].size(), 1u);
  EXPECT_EQ(j["unknown_channels"][0]["name"], "MYSTERY");
  EXPECT_EQ(j["unknown_channels"][0]["count"], kPositions / 5);
  EXPECT_EQ(j["prediction"].size(), 3u);
  EXPECT_GT(j["prediction"][0]["vs_measurement_m"]["count"].get<int>(), 30);
  EXPECT_TRUE(j["prediction"][0]["vs_truth_m"]["rms"].is_null());  // no GROUND_TRUTH
  const std::string md = read_text(out_dir + "/report.md");
  EXPECT_NE(md.find("# Session report: synthetic.lcmlog"), std::string::npos);
  EXPECT_NE(md.find("unknown channel MYSTERY"), std::string::npos);
  EXPECT_EQ(count_lines(read_text(out_dir + "/csv/OBJECT_POSITION.csv")), kPositions + 1);
  EXPECT_EQ(count_lines(read_text(out_dir + "/csv/OBJECT_TRAJECTORY.csv")), 40 + 1);
  EXPECT_FALSE(fs::exists(out_dir + "/csv/MYSTERY.csv"));
  for (const char* png : {"xy.png", "y_time.png", "latency.png", "arm.png"})
    EXPECT_TRUE(fs::exists(out_dir + "/" + png)) << png;
}

// --out, --no-plots, --no-csv, --horizons and --quiet.
TEST_F(ReportProcess, OptionsChooseWhatIsWritten) {
  const std::string out = dir_ + "/chosen";
  const ProcessResult r = run({program("sg-report"), log_, "--out", out, "--no-plots", "--no-csv",
                               "--horizons", "2,8", "--quiet"},
                              60s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out + "/report.md"));
  EXPECT_FALSE(fs::exists(out + "/csv"));
  EXPECT_FALSE(fs::exists(out + "/xy.png"));
  const Json j = read_json(out + "/report.json");
  ASSERT_EQ(j["prediction"].size(), 2u);
  EXPECT_EQ(j["prediction"][1]["h"], 8);
}

// export: one channel as CSV, a header and a row per message, to stdout or a file.
TEST_F(ReportProcess, ExportOneChannel) {
  const ProcessResult r =
      run({program("sg-report"), "export", log_, "--channel", "OBJECT_POSITION", "--csv"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), kPositions + 1);
  EXPECT_EQ(r.out.rfind("recv_utime,", 0), 0u) << r.out.substr(0, 80);
  const std::string file = dir_ + "/traj.csv";
  const ProcessResult f = run({program("sg-report"), "export", log_, "--channel",
                               "OBJECT_TRAJECTORY", "--csv", "--out", file});
  ASSERT_EQ(f.exit_code, 0) << f.err;
  EXPECT_EQ(count_lines(read_text(file)), 40 + 1);
  const ProcessResult none =
      run({program("sg-report"), "export", log_, "--channel", "NOPE", "--csv"});
  EXPECT_NE(none.exit_code, 0);
  EXPECT_EQ(count_lines(none.err), 2) << none.err;  // the skipped bytes, then the error
  EXPECT_NE(none.err.find("channel 'NOPE' is not in"), std::string::npos) << none.err;
}

// channels: one line per channel with its type, count and first/last receive time.
TEST_F(ReportProcess, ChannelsListsEveryChannel) {
  const ProcessResult r = run({program("sg-report"), "channels", log_});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), 3) << r.out;
  std::ostringstream expected;
  expected << "OBJECT_POSITION point3_t " << kPositions << " " << kT0 + 5000 << " "
           << kT0 + (static_cast<int64_t>(kPositions - 1) * 1'000'000 + 15) / 30 + 5000 << "\n";
  EXPECT_NE(r.out.find(expected.str()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("MYSTERY ? 60 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("OBJECT_TRAJECTORY trajectory_t 40 "), std::string::npos) << r.out;
}

// A truncated log still gives a report that names the cut; exit 0.
TEST_F(ReportProcess, TruncatedLogIsReported) {
  const std::string cut = dir_ + "/cut.lcmlog";
  fs::copy_file(log_, cut, fs::copy_options::overwrite_existing);
  const auto size = fs::file_size(cut);
  fs::resize_file(cut, size - 20);
  const ProcessResult r = run({program("sg-report"), cut, "--no-plots", "--no-csv"}, 60s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("truncated at byte"), std::string::npos) << r.out;
  const Json j = read_json(dir_ + "/cut.report/report.json");
  EXPECT_TRUE(j["log"]["truncated"].get<bool>());
  EXPECT_EQ(j["log"]["events"], kPositions + 40 + kPositions / 5 - 1);
}

// Missing, unreadable and non-log files, and bad flags: a non-zero exit and one line.
TEST_F(ReportProcess, BadInputIsOneLine) {
  std::ofstream(dir_ + "/notes.txt") << "not a log\n";
  for (const auto& args : std::vector<std::vector<std::string>>{
           {dir_ + "/missing.lcmlog"},
           {dir_ + "/notes.txt"},
           {"channels", dir_ + "/missing.lcmlog"},
           {"export", dir_ + "/missing.lcmlog", "--channel", "X", "--csv"},
           {log_, "--horizons", "0"},
           {}}) {
    std::vector<std::string> argv = {program("sg-report")};
    argv.insert(argv.end(), args.begin(), args.end());
    const ProcessResult r = run(argv, 20s);
    EXPECT_NE(r.exit_code, 0) << (args.empty() ? "(no args)" : args[0]);
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("sg-report: error: ", 0), 0u) << r.err;
  }
  const ProcessResult missing = run({program("sg-report"), dir_ + "/missing.lcmlog"});
  EXPECT_NE(missing.err.find("missing.lcmlog: No such file or directory"), std::string::npos);
  const ProcessResult text = run({program("sg-report"), dir_ + "/notes.txt"});
  EXPECT_NE(text.err.find("not an LCM log"), std::string::npos) << text.err;
}

// A live session: the real sg-predictor fed by this test, recorded by the real lcm-logger; the
// report counts what the log holds (read by LCM's own reader; at least 90% of what was sent and
// published), and scores the predictions.
TEST(ReportLive, RecordedSessionFromTheRealPredictor) {
  ASSERT_TRUE(multicast_available(7922));
  const std::string dir = make_temp_dir();
  const std::string log = dir + "/live.lcmlog";
  Child predictor({program("sg-predictor"), "--lcm-url", test_url(7922)});
  Child logger({SG_LCM_LOGGER, "--lcm-url=" + test_url(7922), log});
  ASSERT_TRUE(eventually(
      [&] {
        return listening_on_bus(predictor.pid(), 7922) && listening_on_bus(logger.pid(), 7922);
      },
      30s, "sg-predictor and lcm-logger to join the bus"));

  Bus bus(test_url(7922));
  bus.set_guard(vouching_as("sg-vision"));  // the predictor believes positions only from vision
  int64_t newest_source = 0;                // the newest forecast's measurement time
  int positions_heard = 0, forecasts_heard = 0;
  bus.subscribe<stereograsp::trajectory_t>(
      "OBJECT_TRAJECTORY", [&](const stereograsp::trajectory_t& t, const ReceiveInfo&) {
        newest_source = std::max(newest_source, t.source_utime);
        ++forecasts_heard;
      });
  bus.subscribe_raw("OBJECT_POSITION", [&](const RawMessage&) { ++positions_heard; });
  constexpr int kSent = 150;  // 5 s at 30 Hz, real time
  constexpr int kRogue = 20;  // positions from a host without credentials, before the stream
  const int64_t start = now_utime() + 500'000;
  Bus rogue(test_url(7922));
  for (int k = 0; k < kRogue; ++k) {
    stereograsp::point3_t p{};
    p.utime = start - 2'000'000 + k * 1000;
    p.visible = true;
    p.position[0] = 0.65, p.position[2] = 0.2;
    rogue.publish("OBJECT_POSITION", p);
  }
  for (int k = 0; k < kSent; ++k) {
    stereograsp::point3_t p{};
    p.utime = start + static_cast<int64_t>(k) * 33'333;
    p.visible = true;
    const double t = k / 30.0;  // the paper's circle, 0.15 m at 1 rpm
    p.position[0] = 0.5 + 0.15 * std::cos(0.1047 * t);
    p.position[1] = 0.15 * std::sin(0.1047 * t);
    p.position[2] = 0.2;
    p.reprojection_error = 0.2;
    // Paced in real time (the report measures the rate, 30 Hz), reading the bus meanwhile.
    while (now_utime() < p.utime) bus.handle(1ms);
    bus.publish("OBJECT_POSITION", p);
  }
  // sg-predictor forecasts on a 4 Hz grid: it has caught up once it has forecast from the last
  // 0.25 s of the stream.
  const int64_t last_sent = start + int64_t{kSent - 1} * 33'333;
  ASSERT_TRUE(eventually(
      bus, [&] { return newest_source >= last_sent - 250'000; }, 30s,
      "a forecast from the last 0.25 s of the stream"));
  predictor.signal(SIGINT);
  const ProcessResult predicted = predictor.wait(10s);
  int published = -1;
  const auto at = predicted.out.find("published ");
  ASSERT_NE(at, std::string::npos) << predicted.out << predicted.err;
  published = std::stoi(predicted.out.substr(at + 10));
  // Stop lcm-logger once every position and forecast has reached it and it has handled them all.
  ASSERT_TRUE(eventually(
      bus,
      [&] {
        return positions_heard >= kSent && forecasts_heard >= published &&
               handled_bus(logger.pid(), 7922);
      },
      30s, "lcm-logger to read every position and forecast"));
  logger.signal(SIGINT);
  ASSERT_FALSE(logger.wait(10s).timed_out);
  ASSERT_GT(published, 10);
  // What the log holds, by LCM's own reader: a starved lcm-logger loses what LCM's 30-message
  // subscription queue cannot hold (a loaded machine dropped 1 of 150), so the report is held to
  // the log, and the log to most of what was sent.
  const std::map<std::string, int> recorded = events_per_channel(log);
  const int positions = recorded.count("OBJECT_POSITION") ? recorded.at("OBJECT_POSITION") : 0;
  const int forecasts = recorded.count("OBJECT_TRAJECTORY") ? recorded.at("OBJECT_TRAJECTORY") : 0;
  EXPECT_GE(positions, kSent * 9 / 10);
  EXPECT_GE(forecasts, published * 9 / 10);

  const ProcessResult r = run({program("sg-report"), log, "--no-plots"}, 60s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json j = read_json(dir + "/live.report/report.json");
  EXPECT_TRUE(j["log"]["problems"].empty());
  const Json* pos = find_channel(j, "OBJECT_POSITION");
  const Json* traj = find_channel(j, "OBJECT_TRAJECTORY");
  ASSERT_NE(pos, nullptr);
  ASSERT_NE(traj, nullptr);
  EXPECT_EQ((*pos)["count"], positions);
  EXPECT_EQ((*traj)["count"], forecasts);
  EXPECT_EQ((*traj)["decoded"], forecasts);
  EXPECT_NEAR((*pos)["rate_hz"].get<double>(), 30.0, 3.0);
  // Receive minus capture time: positive, and well under a second on one host.
  const Json& lat = j["latency_ms"]["OBJECT_TRAJECTORY"];
  EXPECT_EQ(lat["reference"], "source_utime");
  EXPECT_GT(lat["p50"].get<double>(), 0.0);
  EXPECT_LT(lat["p95"].get<double>(), 1000.0);
  EXPECT_EQ(lat["negative"], 0);
  EXPECT_GT(j["prediction"][0]["vs_measurement_m"]["count"].get<int>(), 5);
  EXPECT_LT(j["prediction"][0]["vs_measurement_m"]["rms"].get<double>(), 0.05);
  EXPECT_EQ(j["unknown_channels"].size(), 0u);
  // sg-predictor vouched as itself and refused the rogue host's positions, by channel and why.
  const Json* refusing = nullptr;
  for (const Json& p : j["processes"]["processes"])
    if (p["name"].get<std::string>().rfind("sg-predictor@", 0) == 0) refusing = &p;
  ASSERT_NE(refusing, nullptr) << j["processes"].dump();
  EXPECT_EQ((*refusing)["vouched_as"], "sg-predictor");
  EXPECT_EQ((*refusing)["unvouched"], kRogue);
  EXPECT_EQ((*refusing)["refusals"], Json::array({"OBJECT_POSITION: 20 unsigned"}));
  EXPECT_NE(read_text(dir + "/live.report/report.md")
                .find("refused messages nobody it believes vouched for: OBJECT_POSITION: 20 "
                      "unsigned"),
            std::string::npos);

  const ProcessResult exported =
      run({program("sg-report"), "export", log, "--channel", "OBJECT_TRAJECTORY", "--csv"});
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_EQ(count_lines(exported.out), forecasts + 1);
  const ProcessResult channels = run({program("sg-report"), "channels", log});
  EXPECT_NE(channels.out.find("OBJECT_POSITION point3_t " + std::to_string(positions) + " "),
            std::string::npos)
      << channels.out;
  EXPECT_NE(channels.out.find("OBJECT_TRAJECTORY trajectory_t " + std::to_string(forecasts)),
            std::string::npos)
      << channels.out;
}

}  // namespace
}  // namespace sg::test
