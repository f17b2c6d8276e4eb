#include "logger/channel_csv.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "common/message_types.hpp"

namespace sg::logger {
namespace {

// One message's cells, with their column names.
class Row {
 public:
  void add_int(std::string name, int64_t value) { add(std::move(name), std::to_string(value)); }

  void add_double(std::string name, double value) {
    if (std::isnan(value)) {
      add(std::move(name), "nan");
      return;
    }
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    add(std::move(name), buffer);
  }

  void add_string(std::string name, const std::string& value) {
    std::string cell = "\"";
    for (char c : value) {
      if (c == '"') cell += '"';
      cell += c;
    }
    cell += '"';
    add(std::move(name), std::move(cell));
  }

  template <class T, size_t N>
  void add_ints(const std::string& name, const T (&values)[N]) {
    for (size_t i = 0; i < N; ++i) add_int(name + "_" + std::to_string(i), values[i]);
  }

  template <size_t N>
  void add_doubles(const std::string& name, const double (&values)[N]) {
    for (size_t i = 0; i < N; ++i) add_double(name + "_" + std::to_string(i), values[i]);
  }

  template <size_t N, size_t M>
  void add_doubles(const std::string& name, const double (&values)[N][M]) {
    for (size_t i = 0; i < N; ++i) add_doubles(name + "_" + std::to_string(i), values[i]);
  }

  std::vector<std::string> names;
  std::vector<std::string> cells;

 private:
  void add(std::string name, std::string cell) {
    names.push_back(std::move(name));
    cells.push_back(std::move(cell));
  }
};

using stereograsp::arm_cmd_t;
using stereograsp::arm_status_t;
using stereograsp::blob_t;
using stereograsp::grasp_command_t;
using stereograsp::grasp_status_t;
using stereograsp::image_t;
using stereograsp::point3_t;
using stereograsp::sim_arm_state_t;
using stereograsp::trajectory_t;

void flatten(const image_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("camera", m.camera);
  row.add_int("frame_number", m.frame_number);
  row.add_int("width", m.width);
  row.add_int("height", m.height);
  row.add_int("row_stride", m.row_stride);
  row.add_int("pixel_format", m.pixel_format);
  row.add_int("size", m.size);  // the bytes themselves are left out
}

void flatten(const blob_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("camera", m.camera);
  row.add_int("frame_number", m.frame_number);
  row.add_int("found", m.found);
  row.add_int("mode", m.mode);
  row.add_doubles("centroid", m.centroid);
  row.add_double("area", m.area);
  row.add_double("major_axis", m.major_axis);
  row.add_double("minor_axis", m.minor_axis);
  row.add_double("orientation", m.orientation);
  row.add_doubles("major_axis_ends", m.major_axis_ends);
  row.add_doubles("minor_axis_ends", m.minor_axis_ends);
  row.add_doubles("bounding_box", m.bounding_box);
  row.add_ints("search_window", m.search_window);
  row.add_int("num_regions", m.num_regions);
  row.add_int("misses", m.misses);
}

void flatten(const point3_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("visible", m.visible);
  row.add_doubles("position", m.position);
  row.add_doubles("position_sigma", m.position_sigma);
  row.add_double("reprojection_error", m.reprojection_error);
  row.add_int("seen_by", m.seen_by);
  row.add_int("flags", m.flags);
}

void flatten(const trajectory_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("source_utime", m.source_utime);
  row.add_int("start_utime", m.start_utime);
  row.add_int("period_us", m.period_us);
  row.add_int("num_points", m.num_points);
  for (size_t i = 0; i < m.position.size(); ++i) {
    const std::string prefix = "position_" + std::to_string(i) + "_";
    for (size_t j = 0; j < m.position[i].size(); ++j) {
      row.add_double(prefix + std::to_string(j), m.position[i][j]);
    }
  }
  row.add_int("occluded_samples", m.occluded_samples);
  row.add_int("status", m.status);
  row.add_int("model", m.model);
  row.add_int("model_order", m.model_order);
}

void flatten(const arm_cmd_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("source_utime", m.source_utime);
  row.add_int("target_utime", m.target_utime);
  row.add_int("sequence", m.sequence);
  row.add_int("mode", m.mode);
  row.add_doubles("position", m.position);
  row.add_doubles("orientation", m.orientation);
  row.add_doubles("joints", m.joints);
  row.add_int("gripper", m.gripper);
  row.add_double("speed", m.speed);
  row.add_string("sender", m.sender);
}

void flatten(const arm_status_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("state", m.state);
  row.add_doubles("joints", m.joints);
  row.add_doubles("tool_position", m.tool_position);
  row.add_doubles("tool_orientation", m.tool_orientation);
  row.add_int("gripper", m.gripper);
  row.add_int("last_received_sequence", m.last_received_sequence);
  row.add_int("last_executed_sequence", m.last_executed_sequence);
  row.add_int("last_rejected_sequence", m.last_rejected_sequence);
  row.add_string("rejection_reason", m.rejection_reason);
  row.add_int("source_utime", m.source_utime);
  row.add_double("interaction_time", m.interaction_time);
  row.add_double("speed", m.speed);
  row.add_string("error", m.error);
}

void flatten(const grasp_command_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("sequence", m.sequence);
  row.add_int("command", m.command);
  row.add_double("standoff", m.standoff);
  row.add_string("sender", m.sender);
}

void flatten(const grasp_status_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_int("source_utime", m.source_utime);
  row.add_int("state", m.state);
  row.add_int("activity", m.activity);
  row.add_int("last_action", m.last_action);
  row.add_doubles("target", m.target);
  row.add_int("target_utime", m.target_utime);
  row.add_int("outcome", m.outcome);
  row.add_string("message", m.message);
}

void flatten(const sim_arm_state_t& m, Row& row) {
  row.add_int("utime", m.utime);
  row.add_doubles("joints", m.joints);
  row.add_doubles("tool_position", m.tool_position);
  row.add_doubles("tool_orientation", m.tool_orientation);
  row.add_double("gripper_opening", m.gripper_opening);
  row.add_int("holding_object", m.holding_object);
}

// Every type of sg::MessageTypes: its fingerprint, name, and exact decoding into a Row.
struct TypeEntry {
  int64_t hash;
  const char* name;
  bool (*decode)(const uint8_t* data, int size, Row& row);
};

template <class T>
bool decode_into(const uint8_t* data, int size, Row& row) {
  T message{};  // value-initialised: GCC cannot see that decode() sets every field
  if (message.decode(data, 0, size) != size) return false;
  flatten(message, row);
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
