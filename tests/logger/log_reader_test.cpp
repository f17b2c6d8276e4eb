// The log reader on logs written here with lcm::LogFile: clean, truncated mid-event, garbage at
// the start, in the middle (also with a false header inside) and at the end, an unknown channel
// and a message of the wrong size: each is reported precisely and every good event is read.

#include "logger/log_reader.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "common/message_types.hpp"
#include "logger/session_stats.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::logger {
namespace {

namespace fs = std::filesystem;

/// Writes events (and raw bytes between them) with lcm::LogFile, as lcm-logger does.
class LogBuilder {
 public:
  explicit LogBuilder(const std::string& path) : log_(path, "w") {}

  /// An event on `channel` at `utime` carrying `data`; returns its size on disk.
  int64_t event(const std::string& channel, int64_t utime, const std::vector<uint8_t>& data) {
    lcm::LogEvent e;
    e.eventnum = 0;
    e.timestamp = utime;
    e.channel = channel;
    e.datalen = static_cast<int32_t>(data.size());
    e.data = const_cast<uint8_t*>(data.data());
    log_.writeEvent(&e);
    return 28 + static_cast<int64_t>(channel.size() + data.size());
  }
  void raw(const std::vector<uint8_t>& bytes) {
    std::fwrite(bytes.data(), 1, bytes.size(), log_.getFilePtr());
  }

 private:
  lcm::LogFile log_;
};

std::vector<uint8_t> position_bytes(int64_t utime) {
  stereograsp::point3_t p{};
  p.utime = utime;
  p.visible = true;
  p.position[0] = 1;
  return encode_message(p);
}

std::vector<uint8_t> garbage(int n) {
  std::vector<uint8_t> g;
  for (int i = 0; i < n; ++i) g.push_back(static_cast<uint8_t>(i * 7 + 3));
  return g;
}

struct ReadBack {
  std::vector<int64_t> utimes;
  std::vector<int64_t> offsets;
  std::vector<LogProblem> problems;
};

ReadBack read_all(const std::string& path) {
  LogReader reader(path);
  ReadBack r;
  LogRecord e;
  while (reader.next(e)) {
    r.utimes.push_back(e.recv_utime);
    r.offsets.push_back(e.offset);
  }
  r.problems = reader.problems();
  return r;
}

const std::vector<int64_t> kFive = {100, 200, 300, 400, 500};

// A clean log: every event, in order, at its offset, and no problem.
TEST(LogReader, CleanLogReadsEveryEvent) {
  const std::string path = test::make_temp_dir() + "/clean.lcmlog";
  int64_t size = 0;
  std::vector<int64_t> offsets;
  {
    LogBuilder b(path);
    for (int64_t t : kFive) {
      offsets.push_back(size);
      size += b.event("OBJECT_POSITION", t, position_bytes(t));
    }
  }
  ASSERT_EQ(static_cast<int64_t>(fs::file_size(path)), size);
  LogReader reader(path);
  std::vector<int64_t> seen;
  LogRecord e;
  while (reader.next(e)) {
    EXPECT_EQ(e.channel, "OBJECT_POSITION");
    EXPECT_EQ(e.size, static_cast<int>(position_bytes(0).size()));
    EXPECT_EQ(e.offset, offsets[seen.size()]);
    seen.push_back(e.recv_utime);
  }
  EXPECT_EQ(seen, kFive);
  EXPECT_TRUE(reader.problems().empty());
  EXPECT_FALSE(reader.truncated());
  EXPECT_EQ(reader.position(), size);
}

/// An event header and body as lcm-logger's format has them, written byte by byte (LCM's own
/// writer takes the channel as a C string, so it cannot write a NUL inside one).
std::vector<uint8_t> raw_event(int64_t number, int64_t utime, const std::string& channel,
                               const std::vector<uint8_t>& data) {
  std::vector<uint8_t> out;
  auto put = [&](uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
  };
  put(0xEDA1DA01u, 4);
  put(static_cast<uint64_t>(number), 8);
  put(static_cast<uint64_t>(utime), 8);
  put(channel.size(), 4);
  put(data.size(), 4);
  out.insert(out.end(), channel.begin(), channel.end());
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

// A channel holding a NUL byte (LCM's reader returns it cut at the NUL) is handed out whole, as
// it is on disk, and the events after it are at their offsets, with no problem reported.
TEST(LogReader, ChannelWithANulIsReadAsOnDisk) {
  const std::string path = test::make_temp_dir() + "/nul.lcmlog";
  const std::string nul_channel("BAD\0CHANNEL", 11);
  std::vector<uint8_t> bytes;
  for (int i = 0; i < 3; ++i) {
    const auto e = raw_event(i, kFive[static_cast<size_t>(i)], i == 1 ? nul_channel : "POS",
                             position_bytes(i));
    bytes.insert(bytes.end(), e.begin(), e.end());
  }
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  LogReader reader(path);
  LogRecord e;
  std::vector<std::string> channels;
  std::vector<int64_t> offsets;
  while (reader.next(e)) {
    channels.push_back(e.channel);
    offsets.push_back(e.offset);
    EXPECT_EQ(std::vector<uint8_t>(e.data, e.data + e.size), position_bytes(e.event_number));
  }
  const int64_t pos = 28 + 3 + static_cast<int64_t>(position_bytes(0).size());
  EXPECT_EQ(channels, (std::vector<std::string>{"POS", nul_channel, "POS"}));
  EXPECT_EQ(offsets, (std::vector<int64_t>{0, pos, pos + 8 + pos}));
  EXPECT_TRUE(reader.problems().empty());
  EXPECT_EQ(reader.position(), static_cast<int64_t>(bytes.size()));
}

// A log cut in the middle of its last event: the others are read, and the cut is named.
TEST(LogReader, TruncatedMidEventIsReported) {
  const std::string path = test::make_temp_dir() + "/cut.lcmlog";
  int64_t last_start = 0;
  {
    LogBuilder b(path);
    for (int64_t t : kFive) {
      const int64_t n = b.event("OBJECT_POSITION", t, position_bytes(t));
      if (t != kFive.back()) last_start += n;
    }
  }
  const int64_t cut = static_cast<int64_t>(fs::file_size(path)) - 7;
  fs::resize_file(path, static_cast<uintmax_t>(cut));
  const ReadBack r = read_all(path);
  EXPECT_EQ(r.utimes, std::vector<int64_t>(kFive.begin(), kFive.end() - 1));
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].kind, LogProblem::Kind::kTruncated);
  EXPECT_EQ(r.problems[0].text,
            "truncated at byte " + std::to_string(last_start) + " of " + std::to_string(cut));
}

// A log cut inside a header (fewer than 28 bytes of the last event left).
TEST(LogReader, TruncatedInsideAHeaderIsReported) {
  const std::string path = test::make_temp_dir() + "/cut_header.lcmlog";
  int64_t first = 0;
  {
    LogBuilder b(path);
    first = b.event("OBJECT_POSITION", 1, position_bytes(1));
    b.event("OBJECT_POSITION", 2, position_bytes(2));
  }
  fs::resize_file(path, static_cast<uintmax_t>(first + 10));
  const ReadBack r = read_all(path);
  EXPECT_EQ(r.utimes, std::vector<int64_t>{1});
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].text,
            "truncated at byte " + std::to_string(first) + " of " + std::to_string(first + 10));
}

// Garbage between events: LCM 1.3.1 refuses the event before it and stops; the reader
// resynchronises on the next event and loses nothing but the garbage.
TEST(LogReader, GarbageInTheMiddleIsSkippedAndReported) {
  const std::string path = test::make_temp_dir() + "/garbage.lcmlog";
  int64_t at = 0;
  {
    LogBuilder b(path);
    for (int64_t t : kFive) {
      at += b.event("OBJECT_POSITION", t, position_bytes(t));
      if (t == 200) b.raw(garbage(37));
    }
  }
  const int64_t two = 28 + 15 + static_cast<int64_t>(position_bytes(0).size());
  EXPECT_EQ(at, 5 * two) << "each event: a 28-byte header, its channel and its body";
  const ReadBack r = read_all(path);
  EXPECT_EQ(r.utimes, kFive);
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].kind, LogProblem::Kind::kSkipped);
  EXPECT_EQ(r.problems[0].text, "37 bytes skipped at offset " + std::to_string(2 * two));
  EXPECT_EQ(r.offsets[2], 2 * two + 37);
}

/// A header (magic, event number, timestamp) claiming `channel_length` and `data_length`.
std::vector<uint8_t> header_claiming(uint32_t channel_length, uint32_t data_length) {
  std::vector<uint8_t> h = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 9};
  for (const uint32_t v : {channel_length, data_length})
    for (int i = 0; i < 4; ++i) h.push_back(static_cast<uint8_t>(v >> (24 - 8 * i)));
  return h;
}

// A header claiming 0x7fffffff bytes of data (LCM's own reader calloc()s INT_MIN bytes for it and
// crashes, measured on main with sg-report), or 0x7fffffff of channel, at the start of a log and
// between events: never handed to LCM; each is a skipped stretch and every real event is read.
TEST(LogReader, HugeEventLengthsAreSkippedNotTrusted) {
  for (const auto& [channel_length, data_length] :
       {std::pair<uint32_t, uint32_t>{15, 0x7fffffff}, {0x7fffffff, 24}, {15, 0x80000000}}) {
    const std::string path = test::make_temp_dir() + "/huge.lcmlog";
    const std::vector<uint8_t> bad = header_claiming(channel_length, data_length);
    {
      LogBuilder b(path);
      b.raw(bad);
      for (int64_t t : kFive) {
        b.event("OBJECT_POSITION", t, position_bytes(t));
        if (t == 300) b.raw(bad);
      }
    }
    const int64_t one = 28 + 15 + static_cast<int64_t>(position_bytes(0).size());
    const ReadBack r = read_all(path);
    EXPECT_EQ(r.utimes, kFive) << channel_length << " " << data_length;
    ASSERT_EQ(r.problems.size(), 2u);
    EXPECT_EQ(r.problems[0].text, "28 bytes skipped at offset 0");
    EXPECT_EQ(r.problems[1].text, "28 bytes skipped at offset " + std::to_string(28 + 3 * one));
  }
}

// Garbage holding a magic followed by absurd lengths (a false header) is skipped too.
TEST(LogReader, FalseHeaderInGarbageIsSkipped) {
  const std::string path = test::make_temp_dir() + "/false_header.lcmlog";
  std::vector<uint8_t> fake = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0,    0, 0, 0, 0,    9, 0, 0,
                               0,    0,    0,    0,    0, 1, 0x7f, 0, 0, 0, 0x7f, 0, 0, 0};
  {
    LogBuilder b(path);
    b.event("OBJECT_POSITION", 1, position_bytes(1));
    b.raw(fake);
    b.event("OBJECT_POSITION", 2, position_bytes(2));
    b.raw({0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0,    0,    0,    9,    0, 0, 0, 0,
           0,    0,    0,    1,    0, 0, 0, 2, 0xff, 0xff, 0xff, 0xf0, 1, 2, 3});  // negative data
                                                                                   // length
    b.event("OBJECT_POSITION", 3, position_bytes(3));
  }
  const ReadBack r = read_all(path);
  EXPECT_EQ(r.utimes, (std::vector<int64_t>{1, 2, 3}));
  ASSERT_EQ(r.problems.size(), 2u);
  EXPECT_EQ(r.problems[0].bytes, 28);
  EXPECT_EQ(r.problems[1].bytes, 31);
}

// Garbage before the first event (LCM skips it itself) and after the last one.
TEST(LogReader, GarbageAtStartAndEndIsReported) {
  const std::string path = test::make_temp_dir() + "/ends.lcmlog";
  int64_t size = 0;
  {
    LogBuilder b(path);
    b.raw(garbage(11));
    size = 11 + b.event("OBJECT_POSITION", 1, position_bytes(1));
    size += b.event("OBJECT_POSITION", 2, position_bytes(2));
    b.raw(garbage(5));
  }
  const ReadBack r = read_all(path);
  EXPECT_EQ(r.utimes, (std::vector<int64_t>{1, 2}));
  ASSERT_EQ(r.problems.size(), 2u);
  EXPECT_EQ(r.problems[0].text, "11 bytes skipped at offset 0");
  EXPECT_EQ(r.problems[1].text, "5 bytes skipped at offset " + std::to_string(size));
}

// An unknown channel and a message of the wrong size are reported by the statistics, and the
// events around them are still read and counted.
TEST(LogReader, UnknownChannelAndWrongSizeAreReported) {
  const std::string path = test::make_temp_dir() + "/odd.lcmlog";
  std::vector<uint8_t> longer = position_bytes(3);
  longer.push_back(0);  // one byte too many
  std::vector<uint8_t> shorter = position_bytes(4);
  shorter.pop_back();  // one byte short
  {
    LogBuilder b(path);
    b.event("OBJECT_POSITION", 1, position_bytes(1));
    b.event("SOMEONE_ELSES", 2, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10});
    b.event("OBJECT_POSITION", 3, longer);
    b.event("OBJECT_POSITION", 4, shorter);
    b.event("LCM_SELF_TEST", 5, {'l', 'c', 'm'});
    b.event("OBJECT_POSITION", 6, position_bytes(6));
  }
  LogReader reader(path);
  SessionStats stats;
  LogRecord e;
  while (reader.next(e)) stats.add(e);
  stats.finish(reader);
  const SessionSummary& s = stats.summary();
  EXPECT_EQ(s.events, 6);
  EXPECT_TRUE(s.problems.empty());
  ASSERT_EQ(s.unknown.size(), 1u);
  EXPECT_EQ(s.unknown[0].name, "SOMEONE_ELSES");
  EXPECT_EQ(s.unknown[0].count, 1);
  EXPECT_EQ(s.unknown[0].fingerprint, "0x0102030405060708");
  ASSERT_EQ(s.lcm_internal.size(), 1u);
  EXPECT_EQ(s.lcm_internal[0].name, "LCM_SELF_TEST");
  const ChannelSummary* pos = nullptr;
  for (const ChannelSummary& c : s.channels)
    if (c.name == "OBJECT_POSITION") pos = &c;
  ASSERT_NE(pos, nullptr);
  EXPECT_EQ(pos->count, 4);
  EXPECT_EQ(pos->decoded, 2);
  EXPECT_EQ(pos->wrong_size, 2);
  EXPECT_EQ(s.wrong_size, 2);
  EXPECT_NE(pos->first_problem.find("wrong size for point3_t"), std::string::npos);
  EXPECT_EQ(s.triangulation.positions, 2);
}

// A missing file, a directory: LogReadError naming the path.
TEST(LogReader, UnreadableFileThrowsWithItsName) {
  const std::string dir = test::make_temp_dir();
  try {
    LogReader reader(dir + "/none.lcmlog");
    FAIL() << "no exception";
  } catch (const LogReadError& e) {
    EXPECT_NE(std::string(e.what()).find("none.lcmlog: No such file"), std::string::npos);
  }
  EXPECT_THROW(LogReader reader(dir), LogReadError);
}

// A text file is no log: no event, all of it skipped.
TEST(LogReader, TextFileHasNoEvent) {
  const std::string path = test::make_temp_dir() + "/notes.txt";
  std::ofstream(path) << "not a log\n";
  const ReadBack r = read_all(path);
  EXPECT_TRUE(r.utimes.empty());
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].text, "10 bytes skipped at offset 0");
}

// Progress is reported by file position and ends at the file's size.
TEST(LogReader, ProgressEndsAtTheFileSize) {
  const std::string path = test::make_temp_dir() + "/progress.lcmlog";
  {
    LogBuilder b(path);
    for (int i = 0; i < 1000; ++i) b.event("OBJECT_POSITION", i, position_bytes(i));
  }
  LogReader reader(path);
  std::vector<int64_t> positions;
  reader.set_progress(
      [&](int64_t pos, int64_t size) {
        EXPECT_EQ(size, reader.file_size());
        positions.push_back(pos);
      },
      10000);
  LogRecord e;
  while (reader.next(e)) {
  }
  ASSERT_GE(positions.size(), 5u);
  EXPECT_EQ(positions.back(), reader.file_size());
  EXPECT_TRUE(std::is_sorted(positions.begin(), positions.end()));
}

}  // namespace
}  // namespace sg::logger
