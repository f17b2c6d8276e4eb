// Drives the log reader (logger/log_reader.hpp, what sg-report, sg-bus-check verify-log and
// sg-predictor train read lcm-logger files with) with any file: the input is written to an
// in-memory file and read to the end with LogReader, as those programs do.
// Asserts, beyond not crashing or allocating without bound:
//  - opening and reading throw nothing (a damaged log is reported, not fatal);
//  - each event handed out is in the file as it says: its header at `offset` holds the magic,
//    its event number, timestamp and lengths, followed by its channel and exactly its data
//    bytes; events come in file order without overlapping;
//  - every byte is accounted for: the events' bytes plus skipped_bytes() and a truncated tail
//    make up the file size.
// Channels holding a NUL byte are asserted too: LCM's C++ reader keeps the channel's length
// (LogEvent::channel.assign(channel, channellen)), and the event's end comes from its checked
// header (d175c5f), so such an event is handed out as it is on disk
// (LogReader.ChannelWithANulIsReadAsOnDisk).

#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz/fuzz_support.hpp"
#include "logger/log_reader.hpp"

namespace {

int64_t big_endian(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return n == 4 ? static_cast<int32_t>(v) : static_cast<int64_t>(v);
}

void check_event(const sg::logger::LogRecord& e, const uint8_t* file, int64_t size) {
  const int64_t h = sg::logger::LogReader::kHeaderSize;
  const int64_t channel = static_cast<int64_t>(e.channel.size());
  SG_FUZZ_CHECK(e.offset >= 0 && e.size >= 0 && e.offset + h + channel + e.size <= size,
                "event at %lld (%lld + %d bytes) outside a file of %lld",
                static_cast<long long>(e.offset), static_cast<long long>(channel), e.size,
                static_cast<long long>(size));
  const uint8_t* p = file + e.offset;
  SG_FUZZ_CHECK(big_endian(p, 4) == static_cast<int32_t>(0xEDA1DA01), "no magic at %lld",
                static_cast<long long>(e.offset));
  SG_FUZZ_CHECK(big_endian(p + 4, 8) == e.event_number && big_endian(p + 12, 8) == e.recv_utime,
                "event number or time differ from the file");
  SG_FUZZ_CHECK(big_endian(p + 20, 4) == channel && big_endian(p + 24, 4) == e.size,
                "lengths differ from the file");
  SG_FUZZ_CHECK(std::memcmp(p + h, e.channel.data(), channel) == 0, "channel differs");
  SG_FUZZ_CHECK(e.size == 0 || std::memcmp(p + h + channel, e.data, e.size) == 0,
                "data differ from the file");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static sg::fuzz::MemoryFile file;
  const std::string& path = file.write(data, size);
  try {
    sg::logger::LogReader reader(path);
    sg::logger::LogRecord event;
    int64_t end_of_last = 0, event_bytes = 0;
    while (reader.next(event)) {
      check_event(event, data, static_cast<int64_t>(size));
      SG_FUZZ_CHECK(event.offset >= end_of_last, "event at %lld overlaps the one before",
                    static_cast<long long>(event.offset));
      end_of_last = event.offset + sg::logger::LogReader::kHeaderSize +
                    static_cast<int64_t>(event.channel.size()) + event.size;
      event_bytes += end_of_last - event.offset;
    }
    int64_t truncated = 0;
    for (const auto& p : reader.problems()) {
      if (p.kind == sg::logger::LogProblem::Kind::kTruncated) truncated += p.bytes;
    }
    if (reader.problem_count() > static_cast<int64_t>(sg::logger::LogReader::kMaxProblems)) {
      return 0;  // problems() holds the first kMaxProblems only: the truncation may be left out
    }
    SG_FUZZ_CHECK(event_bytes + reader.skipped_bytes() + truncated == static_cast<int64_t>(size),
                  "%lld event bytes + %lld skipped + %lld truncated != %zu",
                  static_cast<long long>(event_bytes),
                  static_cast<long long>(reader.skipped_bytes()), static_cast<long long>(truncated),
                  size);
  } catch (const std::exception& e) {
    SG_FUZZ_CHECK(false, "LogReader threw: %s", e.what());
  }
  return 0;
}
