#include "common/bus_check.hpp"

#include <array>
#include <cctype>
#include <functional>
#include <limits>

#include "common/message_types.hpp"
#include "common/safe_decode.hpp"

namespace sg::bus_check {

SendSettings read_send_settings(const Config& config) {
  SendSettings s;
  Section c(config, "bus_check");
  c.number("count", s.count, Range::at_least(0), "messages to send, 0 for no limit");
  c.number("rate_hz", s.rate_hz, Range::above(0), "messages per second");
  c.done();
  return s;
}
namespace {

using namespace stereograsp;

/// splitmix64: a small, well-mixed generator; the same seed gives the same stream everywhere.
class Pattern {
 public:
  explicit Pattern(int64_t seed) : state_(static_cast<uint64_t>(seed)) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double real() { return static_cast<double>(next() >> 11) * 0x1.0p-53 * 20.0 - 10.0; }
  int32_t below(int32_t n) { return static_cast<int32_t>(next() % static_cast<uint64_t>(n)); }
  int8_t small() { return static_cast<int8_t>(below(5)); }
  int64_t integer() { return static_cast<int64_t>(next() >> 1); }
  bool flag() { return (next() & 1U) != 0; }
  std::string text() {
    std::string s(static_cast<size_t>(below(40)), ' ');
    for (char& c : s) c = static_cast<char>('a' + below(26));
    return s;
  }
  template <size_t N>
  void fill(double (&values)[N]) {
    for (double& v : values) v = real();
  }
  template <size_t N, size_t M>
  void fill(double (&values)[N][M]) {
    for (auto& row : values) fill(row);
  }
  template <size_t N>
  void fill(int32_t (&values)[N]) {
    for (int32_t& v : values) v = below(1000);
  }

 private:
  uint64_t state_;
};

void fill(image_t& m, Pattern& p) {
  m.camera = p.flag() ? image_t::LEFT : image_t::RIGHT;
  m.frame_number = p.integer();
  m.width = p.below(64);
  m.height = p.below(48);
  m.pixel_format = image_t::FORMAT_GRAY8;
  m.row_stride = m.width;
  m.size = p.below(2048);
  m.data.resize(static_cast<size_t>(m.size));
  for (uint8_t& byte : m.data) byte = static_cast<uint8_t>(p.next());
}
void fill(blob_t& m, Pattern& p) {
  m.camera = p.flag() ? blob_t::LEFT : blob_t::RIGHT;
  m.frame_number = p.integer();
  m.found = p.flag();
  m.mode = p.flag() ? blob_t::MODE_TRACKING : blob_t::MODE_FULL_FRAME;
  p.fill(m.centroid);
  m.area = p.real();
  m.major_axis = p.real();
  m.minor_axis = p.real();
  m.orientation = p.real();
  p.fill(m.major_axis_ends);
  p.fill(m.minor_axis_ends);
  p.fill(m.bounding_box);
  p.fill(m.search_window);
  m.num_regions = p.below(100);
  m.misses = p.below(100);
}
void fill(point3_t& m, Pattern& p) {
  m.visible = p.flag();
  p.fill(m.position);
  p.fill(m.position_sigma);
  m.reprojection_error = p.real();
  m.seen_by = p.small();
  m.flags = p.below(8);
}
void fill(trajectory_t& m, Pattern& p) {
  m.source_utime = p.integer();
  m.start_utime = p.integer();
  m.period_us = p.below(1000000);
  m.num_points = p.below(17);
  m.position.resize(static_cast<size_t>(m.num_points));
  for (auto& point : m.position) {
    point.resize(3);  // lcm-gen's C++ for [n][3] is a vector of vectors: size each one
    for (double& v : point) v = p.real();
  }
  m.occluded_samples = p.below(17);
  m.status = p.small();
  m.model = p.small();
  m.model_order = p.below(32);
}
void fill(arm_cmd_t& m, Pattern& p) {
  m.source_utime = p.integer();
  m.target_utime = p.integer();
  m.sequence = p.integer();
  m.mode = p.small();
  p.fill(m.position);
  p.fill(m.orientation);
  p.fill(m.joints);
  m.gripper = p.small();
  m.speed = p.real();
  m.sender = p.text();
}
void fill(arm_status_t& m, Pattern& p) {
  m.state = p.small();
  p.fill(m.joints);
  p.fill(m.tool_position);
  p.fill(m.tool_orientation);
  m.gripper = p.small();
  m.last_received_sequence = p.integer();
  m.last_executed_sequence = p.integer();
  m.last_rejected_sequence = p.integer();
  m.rejection_reason = p.text();
  m.source_utime = p.integer();
  m.interaction_time = p.real();
  m.speed = p.real();
  m.error = p.text();
}
void fill(grasp_command_t& m, Pattern& p) {
  m.sequence = p.integer();
  m.command = p.small();
  m.standoff = p.real();
  m.sender = p.text();
}
void fill(grasp_status_t& m, Pattern& p) {
  m.source_utime = p.integer();
  m.state = p.small();
  m.activity = p.small();
  m.last_action = p.small();
  p.fill(m.target);
  m.target_utime = p.integer();
  m.outcome = p.small();
  m.message = p.text();
  m.command_sequence = p.integer();
  m.command_result = p.small();
  m.command_reason = p.text();
}
void fill(sim_arm_state_t& m, Pattern& p) {
  p.fill(m.joints);
  p.fill(m.tool_position);
  p.fill(m.tool_orientation);
  m.gripper_opening = p.real();
  m.holding_object = p.flag();
}
void fill(process_status_t& m, Pattern& p) {
  m.process = p.text();
  m.host = p.text();
  m.pid = p.below(100000);
  m.messages_received = p.integer();
  m.decode_errors = p.integer();
  m.handler_errors = p.integer();
  m.refused_inputs = p.integer();
  m.publish_errors = p.integer();
  m.last_problem = p.text();
}

template <class T>
std::vector<uint8_t> encode_as(int64_t utime) {
  T message{};
  message.utime = utime;
  Pattern pattern(utime);
  fill(message, pattern);
  return encode_message(message);
}

template <class T>
std::optional<int64_t> decode_utime(const uint8_t* data, int size) {
  T message{};
  if (!safe_decode(data, size, message)) return std::nullopt;
  return message.utime;
}

struct TypeEntry {
  std::string name;
  std::string channel;
  std::function<std::vector<uint8_t>(int64_t)> encode;
  std::function<std::optional<int64_t>(const uint8_t*, int)> decode_utime;
};

const std::vector<TypeEntry>& types() {
  static const std::vector<TypeEntry> entries = [] {
    std::vector<TypeEntry> list;
    for_each_message_type([&]<class T>() {
      std::string upper = T::getTypeName();
      for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      list.push_back({T::getTypeName(), kChannelPrefix + upper, encode_as<T>, decode_utime<T>});
    });
    return list;
  }();
  return entries;
}

}  // namespace

int type_count() { return static_cast<int>(types().size()); }
std::string channel(int type_index) { return types().at(static_cast<size_t>(type_index)).channel; }
std::string type_name(int type_index) { return types().at(static_cast<size_t>(type_index)).name; }

std::vector<uint8_t> encode(int type_index, int64_t utime) {
  return types().at(static_cast<size_t>(type_index)).encode(utime);
}

std::optional<Verdict> verify(const std::string& channel_name, const uint8_t* data, int size) {
  for (int i = 0; i < type_count(); ++i) {
    const TypeEntry& entry = types()[static_cast<size_t>(i)];
    if (entry.channel != channel_name) continue;
    Verdict verdict;
    verdict.type_index = i;
    const std::optional<int64_t> utime = entry.decode_utime(data, size);
    if (!utime) return verdict;
    verdict.utime = *utime;
    const std::vector<uint8_t> expected = entry.encode(*utime);
    verdict.intact = expected.size() == static_cast<size_t>(size) &&
                     std::equal(expected.begin(), expected.end(), data);
    return verdict;
  }
  return std::nullopt;
}

}  // namespace sg::bus_check
