#include "logger/log_reader.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>

#include "common/log_format.hpp"
#include "common/vouch_trailer.hpp"

namespace sg::logger {
namespace {

using log_format::EventHeader;
using log_format::kMagic;

/// LCM prints its own line on stderr for each damaged stretch ("Invalid header after log data");
/// the reader reports the stretch itself, so LCM's line is sent to /dev/null while LCM reads.
/// glibc's `stderr` is an assignable variable that liblcm's fprintf calls read at call time.
class QuietLcm {
 public:
  QuietLcm() : saved_(stderr) {
    static FILE* const sink = std::fopen("/dev/null", "w");
    if (sink != nullptr) stderr = sink;
  }
  ~QuietLcm() { stderr = saved_; }

 private:
  FILE* saved_;
};

/// The offset of the first magic at or after `pos`, reading `chunk` bytes at a time; -1 when there
/// is none before the end of the file, or the file cannot be read.
int64_t next_magic(FILE* f, int64_t pos, int64_t file_size, std::vector<uint8_t>& chunk) {
  while (pos + 4 <= file_size) {
    if (fseeko(f, pos, SEEK_SET) != 0) return -1;
    const size_t got = std::fread(chunk.data(), 1, chunk.size(), f);
    if (got < 4) return -1;
    for (size_t i = 0; i + 4 <= got; ++i) {
      if (chunk[i] == kMagic[0] && std::memcmp(&chunk[i], kMagic, 4) == 0) {
        return pos + static_cast<int64_t>(i);
      }
    }
    pos += static_cast<int64_t>(got) - 3;  // a magic may straddle the chunk's end
  }
  return -1;
}

/// What a magic found at some offset starts.
enum class Candidate {
  kEvent,       ///< a whole event: its header read, the file just after the header
  kNotAHeader,  ///< a magic inside garbage or data
  kOverflow,    ///< a header whose event runs past the end of the file
  kUnreadable,  ///< the header could not be read
};

/// Reads and judges the header at `q` (into `h` when it is one; a magic must be at `q`).
Candidate read_candidate(FILE* f, int64_t q, int64_t file_size, EventHeader& h) {
  if (q + LogReader::kHeaderSize > file_size) return Candidate::kOverflow;
  uint8_t header[LogReader::kHeaderSize];
  fseeko(f, q, SEEK_SET);
  if (std::fread(header, 1, LogReader::kHeaderSize, f) != LogReader::kHeaderSize) {
    return Candidate::kUnreadable;
  }
  if (!log_format::parse_header(header, h)) return Candidate::kNotAHeader;
  if (!h.fits(q, file_size)) return Candidate::kOverflow;
  return Candidate::kEvent;
}

/// True when a whole, plausible event starts exactly at `q` (its magic there, its lengths within
/// bounds and the file, its header then in `h`); the file is left positioned at `q`.
bool event_at(FILE* f, int64_t q, int64_t file_size, EventHeader& h) {
  const bool good = read_candidate(f, q, file_size, h) == Candidate::kEvent;
  fseeko(f, q, SEEK_SET);
  return good;
}

}  // namespace

namespace {
/// A recorded message's vouching trailer (common/vouch_trailer.hpp) is not part of its type:
/// readers get the LCM encoding, and who vouched for it beside.
void take_off_trailer(LogRecord& out) {
  out.recorded_size = out.size;
  const TrailerParse p = parse_vouch_trailer(out.data, static_cast<size_t>(std::max(out.size, 0)));
  out.vouched_by.clear();
  if (p.kind != TrailerParse::kFound) return;
  out.size = static_cast<int>(p.payload_size);
  out.vouched_by = p.trailer.sender;
}
}  // namespace

LogReader::LogReader(const std::string& path) : path_(path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw LogReadError(path + ": " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw LogReadError(path + ": is a directory, not a log");
  FILE* probe = std::fopen(path.c_str(), "rb");
  if (probe == nullptr) throw LogReadError(path + ": " + std::strerror(errno));
  std::fclose(probe);
  file_size_ = static_cast<int64_t>(st.st_size);
  log_ = std::make_unique<lcm::LogFile>(path, "r");
  if (!log_->good()) throw LogReadError(path + ": cannot be opened as an LCM log");
}

LogReader::~LogReader() = default;

void LogReader::set_progress(std::function<void(int64_t, int64_t)> callback, int64_t every_bytes) {
  progress_ = std::move(callback);
  progress_every_ = every_bytes > 0 ? every_bytes : 1;
  progress_next_ = 0;
}

void LogReader::report_progress(bool force) {
  if (!progress_) return;
  if (!force && end_of_last_ < progress_next_) return;
  progress_(end_of_last_, file_size_);
  progress_next_ = end_of_last_ + progress_every_;
}

void LogReader::add_problem(LogProblem::Kind kind, int64_t offset, int64_t bytes) {
  ++problem_count_;
  if (kind == LogProblem::Kind::kSkipped) skipped_bytes_ += bytes;
  if (kind == LogProblem::Kind::kTruncated) truncated_ = true;
  if (problems_.size() >= kMaxProblems) return;
  LogProblem p;
  p.kind = kind;
  p.offset = offset;
  p.bytes = bytes;
  p.text =
      kind == LogProblem::Kind::kSkipped
          ? std::to_string(bytes) + " bytes skipped at offset " + std::to_string(offset)
          : "truncated at byte " + std::to_string(offset) + " of " + std::to_string(file_size_);
  problems_.push_back(std::move(p));
}

bool LogReader::next(LogRecord& out) {
  if (done_) return false;
  FILE* f = log_->getFilePtr();
  const lcm::LogEvent* event = nullptr;
  // LCM's reader trusts the lengths in a header; it is given only an event checked here. Anything
  // else (garbage, a damaged header) goes to recover(), which reads around it.
  EventHeader header;
  if (end_of_last_ < file_size_ && event_at(f, end_of_last_, file_size_, header)) {
    QuietLcm quiet;
    event = log_->readNextEvent();
  }
  if (event == nullptr) {
    if (end_of_last_ < file_size_ && recover(out)) {
      ++events_;
      report_progress(false);
      return true;
    }
    done_ = true;
    report_progress(true);
    return false;
  }
  // The event LCM read is the one checked at end_of_last_. Its end comes from the header, not
  // from the file position: LCM reads 4 bytes past an event to look for the next magic and does
  // not step back when fewer than 4 are left, and it returns a channel with a NUL inside as
  // shorter than it is on disk (both found by fuzz/log_reader_fuzz).
  const int64_t start = end_of_last_;
  end_of_last_ = start + header.event_size();
  fseeko(f, end_of_last_, SEEK_SET);
  out.channel = event->channel;
  out.recv_utime = event->timestamp;
  out.event_number = event->eventnum;
  out.data = static_cast<const uint8_t*>(event->data);
  out.size = event->datalen;
  out.offset = start;
  take_off_trailer(out);
  ++events_;
  report_progress(false);
  return true;
}

// LCM stopped short of the end: find the next whole event ourselves, read it, and hand the file
// back to LCM just after it. The stretch from the last good event to the found one is skipped.
bool LogReader::recover(LogRecord& out) {
  FILE* f = log_->getFilePtr();
  const int64_t skip_start = end_of_last_;
  int64_t first_overflow = -1;  // a header whose event runs past the end of the file
  std::vector<uint8_t> chunk(1 << 16);
  int64_t pos = skip_start;
  while (pos + 4 <= file_size_) {
    const int64_t q = next_magic(f, pos, file_size_, chunk);
    if (q < 0) break;
    EventHeader h;
    const Candidate candidate = read_candidate(f, q, file_size_, h);
    if (candidate == Candidate::kUnreadable) break;
    if (candidate == Candidate::kOverflow && first_overflow < 0) first_overflow = q;
    if (candidate != Candidate::kEvent) {
      pos = q + 1;
      continue;
    }
    buffer_.resize(static_cast<size_t>(h.channel_length + h.data_length));
    if (std::fread(buffer_.data(), 1, buffer_.size(), f) != buffer_.size()) break;
    if (q > skip_start) add_problem(LogProblem::Kind::kSkipped, skip_start, q - skip_start);
    out.channel.assign(reinterpret_cast<const char*>(buffer_.data()),
                       static_cast<size_t>(h.channel_length));
    out.recv_utime = h.recv_utime;
    out.event_number = h.event_number;
    out.data = buffer_.data() + h.channel_length;
    out.size = static_cast<int>(h.data_length);
    out.offset = q;
    take_off_trailer(out);
    end_of_last_ = q + kHeaderSize + h.channel_length + h.data_length;
    fseeko(f, end_of_last_, SEEK_SET);  // LCM goes on from here
    return true;
  }
  note_lost_tail(skip_start, first_overflow);
  return false;
}

void LogReader::note_lost_tail(int64_t skip_start, int64_t first_overflow) {
  if (first_overflow >= 0) {
    if (first_overflow > skip_start)
      add_problem(LogProblem::Kind::kSkipped, skip_start, first_overflow - skip_start);
    add_problem(LogProblem::Kind::kTruncated, first_overflow, file_size_ - first_overflow);
  } else if (file_size_ > skip_start) {
    add_problem(LogProblem::Kind::kSkipped, skip_start, file_size_ - skip_start);
  }
  end_of_last_ = file_size_;
}

}  // namespace sg::logger
