#include "logger/channel_csv.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/message_fields.hpp"
#include "common/message_types.hpp"
#include "common/safe_decode.hpp"

namespace sg::logger {
namespace {

// One message's cells, with their column names.
class Row {
 public:
  void add_int(std::string name, int64_t value) { push(std::move(name), std::to_string(value)); }

  void add_double(std::string name, double value) {
    if (std::isnan(value)) {
      push(std::move(name), "nan");
      return;
    }
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    push(std::move(name), buffer);
  }

  void add_string(std::string name, const std::string& value) {
    std::string cell = "\"";
    for (char c : value) {
      if (c == '"') cell += '"';
      cell += c;
    }
    cell += '"';
    push(std::move(name), std::move(cell));
  }

  /// One field, as common/message_fields.hpp names it: numbers and booleans as they are,
  /// strings quoted, arrays flattened with _i suffixes; byte arrays (image data) left out.
  template <class T>
  void add(const std::string& name, const T& value) {
    if constexpr (std::is_same_v<T, std::vector<uint8_t>>) {
      return;  // the bytes themselves are left out (the message's size field stays)
    } else if constexpr (std::is_same_v<T, std::string>) {
      add_string(name, value);
    } else if constexpr (std::is_floating_point_v<T>) {
      add_double(name, value);
    } else if constexpr (std::is_arithmetic_v<T>) {
      add_int(name, static_cast<int64_t>(value));
    } else {  // a fixed array or a vector of anything else
      for (size_t i = 0; i < std::size(value); ++i) add(name + "_" + std::to_string(i), value[i]);
    }
  }

  std::vector<std::string> names;
  std::vector<std::string> cells;

 private:
  void push(std::string name, std::string cell) {
    names.push_back(std::move(name));
    cells.push_back(std::move(cell));
  }
};

// Every type of sg::MessageTypes: its fingerprint, name, and exact decoding into a Row.
struct TypeEntry {
  int64_t hash;
  const char* name;
  bool (*decode)(const uint8_t* data, int size, Row& row);
};

template <class T>
bool decode_into(const uint8_t* data, int size, Row& row) {
  T message{};  // value-initialised: GCC cannot see that decode() sets every field
  if (!safe_decode(data, size, message)) return false;
  visit_fields(message, row);
  return true;
}

const std::vector<TypeEntry>& type_table() {
  static const std::vector<TypeEntry> table = [] {
    std::vector<TypeEntry> entries;
    sg::for_each_message_type([&]<class T>() {
      entries.push_back({T::getHash(), T::getTypeName(), &decode_into<T>});
    });
    return entries;
  }();
  return table;
}

// The index in type_table() of the type whose fingerprint starts `data`, or -1.
int type_index(const uint8_t* data, int size) {
  if (data == nullptr || size < 8) return -1;
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[i];
  const std::vector<TypeEntry>& table = type_table();
  for (size_t i = 0; i < table.size(); ++i) {
    if (static_cast<uint64_t>(table[i].hash) == hash) return static_cast<int>(i);
  }
  return -1;
}

void write_line(std::ostream& out, const std::vector<std::string>& cells) {
  for (size_t i = 0; i < cells.size(); ++i) {
    if (i > 0) out << ',';
    out << cells[i];
  }
  out << '\n';
}

}  // namespace

bool CsvWriter::write(std::ostream& out, int64_t recv_utime, const uint8_t* data, int size) {
  const int index = type_index(data, size);
  if (index < 0 || (type_index_ >= 0 && index != type_index_)) return false;
  Row row;
  row.add_int("recv_utime", recv_utime);
  if (!type_table()[index].decode(data, size, row)) return false;

  if (type_index_ < 0) {
    type_index_ = index;
    type_name_ = type_table()[index].name;
    header_ = row.names;
    write_line(out, header_);
  }
  if (row.names == header_) {
    write_line(out, row.cells);
  } else {
    ++misaligned_rows_;
    std::unordered_map<std::string, size_t> at;
    for (size_t i = 0; i < row.names.size(); ++i) at.emplace(row.names[i], i);
    std::vector<std::string> cells;
    cells.reserve(header_.size());
    for (const std::string& name : header_) {
      auto found = at.find(name);
      cells.push_back(found == at.end() ? std::string() : row.cells[found->second]);
    }
    write_line(out, cells);
  }
  ++rows_;
  return true;
}

ChannelCsv::ChannelCsv(std::string dir) : dir_(std::move(dir)) {}

std::optional<std::string> ChannelCsv::type_name(const uint8_t* data, int size) {
  const int index = type_index(data, size);
  if (index < 0) return std::nullopt;
  Row row;
  if (!type_table()[index].decode(data, size, row)) return std::nullopt;
  return std::string(type_table()[index].name);
}

std::string ChannelCsv::file_name(const std::string& channel) {
  std::string name = channel.empty() ? "_" : channel;
  for (char& c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '-' || c == '.';
    if (!keep) c = '_';
  }
  if (name == "." || name == "..") name = "_";
  return name + ".csv";
}

bool ChannelCsv::add(const std::string& channel, int64_t recv_utime, const uint8_t* data,
                     int size) {
  auto it = channels_.find(channel);
  if (it == channels_.end()) {
    if (!type_name(data, size)) return false;
    // Channels whose names sanitise alike ("A/B", "A_B") get distinct files: A_B.csv, A_B.2.csv.
    std::string name = file_name(channel);
    for (int n = 2; used_names_.count(name) > 0; ++n) {
      name = file_name(channel);
      name.insert(name.size() - 4, "." + std::to_string(n));
    }
    std::error_code error;
    std::filesystem::create_directories(dir_, error);
    if (error) {
      throw std::runtime_error("cannot create directory '" + dir_ + "': " + error.message());
    }
    Channel entry;
    entry.path = (std::filesystem::path(dir_) / name).string();
    entry.out = std::make_unique<std::ofstream>(entry.path, std::ios::binary | std::ios::trunc);
    if (!*entry.out) throw std::runtime_error("cannot create CSV file '" + entry.path + "'");
    used_names_.insert(name);
    files_.push_back(entry.path);
    it = channels_.emplace(channel, std::move(entry)).first;
  }
  Channel& entry = it->second;
  if (!entry.writer.write(*entry.out, recv_utime, data, size)) return false;
  if (!*entry.out) throw std::runtime_error("cannot write CSV file '" + entry.path + "'");
  return true;
}

void ChannelCsv::flush() {
  for (auto& [channel, entry] : channels_) {
    entry.out->flush();
    if (!*entry.out) throw std::runtime_error("cannot write CSV file '" + entry.path + "'");
  }
}

}  // namespace sg::logger
