#pragma once

/// A streaming reader of lcm-logger files over lcm::LogFile: one event at a time, constant
/// memory, and every problem of a damaged log named precisely while the rest is still read.
///
///     sg::logger::LogReader reader("session.lcmlog");   // throws LogReadError if unreadable
///     reader.set_progress([](int64_t pos, int64_t size) { show(pos, size); });
///     sg::logger::LogRecord event;
///     while (reader.next(event)) use(event.channel, event.recv_utime, event.data, event.size);
///     for (const auto& p : reader.problems()) std::puts(p.text.c_str());
///
/// An event on disk is a 28-byte header (magic 0xEDA1DA01, int64 event number, int64 timestamp,
/// int32 channel length, int32 data length, all big-endian), the channel, then the data.
///
/// What LCM 1.3.1 does with damage, measured (tests/logger/log_reader_test.cpp): its reader skips
/// bytes up to the next magic *before* an event, but it refuses an event that is *followed* by
/// anything other than a magic (it prints "Invalid header after log data") and then returns NULL
/// as if the log had ended; a header with an absurd channel or data length ends the log too. The
/// reader here notices every early NULL (the file position is short of the end), reads the refused
/// event itself when it is whole, finds the next plausible header and hands the file back to
/// lcm::LogFile there, so that one bad stretch costs only its own bytes. Skipped stretches are
/// detected by comparing the file position before and after each event with the event's size.
/// LCM's own stderr lines about the damage are silenced while it reads (the problems list says
/// it all); `stderr` is swapped for /dev/null only inside readNextEvent(), so do not read logs
/// while another thread writes to stderr through the C stdio `stderr`.

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace lcm {
class LogFile;
}

namespace sg::logger {

/// The file cannot be opened or read at all.
class LogReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One event of the log; data is valid until the next call to LogReader::next().
struct LogRecord {
  std::string channel;
  int64_t recv_utime = 0;  ///< the event's timestamp: lcm-logger's receive time
  int64_t event_number = 0;
  const uint8_t* data = nullptr;
  int size = 0;  ///< the LCM encoding's bytes: a vouching trailer (docs/security.md) taken off
  int64_t offset = 0;      ///< byte offset of the event's header in the file
  int recorded_size = 0;   ///< the bytes as recorded, trailer included
  std::string vouched_by;  ///< the sender its trailer names ("" when it carries none)
};

/// Something wrong with the file itself (not with a message inside it).
struct LogProblem {
  enum class Kind { kSkipped, kTruncated };
  Kind kind = Kind::kSkipped;
  int64_t offset = 0;  ///< where the bad stretch starts
  int64_t bytes = 0;   ///< how long it is (to the end of the file for a truncation)
  std::string text;    ///< "37 bytes skipped at offset 120", "truncated at byte 1000 of 1017"
};

/// Reads an lcm-logger file start to end in one pass.
class LogReader {
 public:
  /// Size of an event header on disk.
  static constexpr int kHeaderSize = 28;
  /// Most problems kept in problems() (all are counted in problem_count()).
  static constexpr size_t kMaxProblems = 1000;

  /// Opens `path`; throws LogReadError naming the file and the reason when it cannot.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  /// The next good event, or false at the end of the file.
  bool next(LogRecord& out);

  /// Called with (position, file size) at most every `every_bytes` of progress, and at the end.
  void set_progress(std::function<void(int64_t, int64_t)> callback, int64_t every_bytes = 4 << 20);

  int64_t file_size() const { return file_size_; }
  int64_t position() const { return end_of_last_; }
  int64_t events() const { return events_; }
  const std::vector<LogProblem>& problems() const { return problems_; }
  int64_t problem_count() const { return problem_count_; }
  int64_t skipped_bytes() const { return skipped_bytes_; }
  bool truncated() const { return truncated_; }

 private:
  bool recover(LogRecord& out);
  /// No whole event from `skip_start` to the end: the stretch is skipped, or truncated from the
  /// first header whose event runs past the end (`first_overflow`, -1 if none); all is read.
  void note_lost_tail(int64_t skip_start, int64_t first_overflow);
  void add_problem(LogProblem::Kind kind, int64_t offset, int64_t bytes);
  void report_progress(bool force);

  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t file_size_ = 0;
  int64_t end_of_last_ = 0;  ///< file offset just past the last event handed out
  int64_t events_ = 0;
  bool done_ = false;
  bool truncated_ = false;
  std::vector<uint8_t> buffer_;  ///< an event read by the reader itself
  std::vector<LogProblem> problems_;
  int64_t problem_count_ = 0;
  int64_t skipped_bytes_ = 0;
  std::function<void(int64_t, int64_t)> progress_;
  int64_t progress_every_ = 4 << 20;
  int64_t progress_next_ = 0;
};

}  // namespace sg::logger
