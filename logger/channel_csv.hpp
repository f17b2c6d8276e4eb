#pragma once

/// CSV files of a session's messages: one file per channel, one row per message, one column
/// per field, written as the log is read (open files, constant memory).
///
///     ChannelCsv csv("session-report/csv");
///     for (const Event& e : log)          // every event of an lcm-logger file
///       csv.add(e.channel, e.recv_utime, e.data, e.size);   // false: not a stereograsp type
///     csv.flush();
///     for (const std::string& path : csv.files()) std::cout << path << "\n";
///
/// and one channel to any stream (`sg-report export LOG --channel NAME --csv`):
///
///     CsvWriter writer;                   // takes the type of the first message it accepts
///     for (const Event& e : log)
///       if (e.channel == name) writer.write(std::cout, e.recv_utime, e.data, e.size);
///
/// Format (RFC 4180 style, "\n" line ends): a header row, then a row per message.
///  - Columns: recv_utime (the log's receive time, microseconds since the Unix epoch), then
///    the type's fields in .lcm order under their own names.
///  - Arrays are flattened with an _i suffix per index: position_0, position_1, position_2;
///    blob_t.major_axis_ends_0_1; trajectory_t.position_<point>_<xyz>.
///  - Integers and booleans (LCM booleans are 0 or 1) in decimal; doubles with %.17g so the
///    text reads back to the same double; NaN as "nan", infinities as "inf" and "-inf".
///  - Strings are always quoted, with any '"' doubled ("say ""hi"", ok").
///  - image_t's pixel bytes are left out; its `size` column keeps their count.
///
/// A message is accepted when its first 8 bytes are the fingerprint of a stereograsp type
/// (sg::MessageTypes) and the bytes decode as that type using exactly `size` bytes; anything
/// else (another package's type, LCM_SELF_TEST, a truncated or over-long message) is refused
/// and writes nothing.

#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace sg::logger {

/// Writes messages of one stereograsp type as CSV to any std::ostream: the header before the
/// first row, then a row per write().
///
/// Columns are fixed by the first message. trajectory_t has a column per predicted point, so a
/// later trajectory with a different num_points is written under the first one's columns:
/// points it lacks are empty cells, points beyond are left out (num_points still tells the
/// truth); such rows are counted in misaligned_rows().
class CsvWriter {
 public:
  /// A writer that takes the type of the first message it accepts.
  CsvWriter() = default;

  /// Writes one row (and first the header) when `data` decodes exactly as this writer's type
  /// (or, before the first row, as any stereograsp type). Returns false, writing nothing,
  /// otherwise.
  bool write(std::ostream& out, int64_t recv_utime, const uint8_t* data, int size);

  /// The type's name (e.g. "point3_t"), empty before the first accepted message.
  const std::string& type_name() const { return type_name_; }
  /// The header's column names, empty before the first accepted message.
  const std::vector<std::string>& columns() const { return header_; }
  /// Rows written.
  int64_t rows() const { return rows_; }
  /// Rows whose columns differed from the header's (see the class comment).
  int64_t misaligned_rows() const { return misaligned_rows_; }

 private:
  int type_index_ = -1;
  std::string type_name_;
  std::vector<std::string> header_;
  int64_t rows_ = 0;
  int64_t misaligned_rows_ = 0;
};

/// One CSV file per channel in a directory: dir/<CHANNEL>.csv.
class ChannelCsv {
 public:
  /// Files go to `dir`, which is created (with its parents) when the first file is opened.
  explicit ChannelCsv(std::string dir);

  /// Appends the message to its channel's file, opening the file (and writing the header) on
  /// the channel's first accepted message. Returns false, writing nothing, for bytes that do
  /// not decode exactly as a stereograsp type, or as the type the channel's file already
  /// holds. Throws std::runtime_error naming the path when a file cannot be created or written.
  bool add(const std::string& channel, int64_t recv_utime, const uint8_t* data, int size);

  /// Paths of the files written so far, in the order they were opened.
  std::vector<std::string> files() const { return files_; }
  /// Flushes every open file (they are also flushed and closed on destruction).
  void flush();

  /// The stereograsp type that `data` decodes as exactly (e.g. "point3_t"), or nullopt.
  static std::optional<std::string> type_name(const uint8_t* data, int size);
  /// The file name for a channel: the channel with every character other than letters,
  /// digits, '_', '-' and '.' replaced by '_', plus ".csv" ("BLOB_LEFT" -> "BLOB_LEFT.csv").
  static std::string file_name(const std::string& channel);

 private:
  struct Channel {
    std::string path;
    std::unique_ptr<std::ofstream> out;
    CsvWriter writer;
  };

  std::string dir_;
  std::map<std::string, Channel> channels_;
  std::set<std::string> used_names_;
  std::vector<std::string> files_;
};

}  // namespace sg::logger
