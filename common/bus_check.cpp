#include "common/bus_check.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>
#include <thread>

#include "common/message_fields.hpp"
#include "common/message_types.hpp"
#include "common/safe_decode.hpp"

namespace sg::bus_check {

SendSettings read_send_settings(const Config& config) {
  SendSettings s;
  Section c(config, "bus_check");
  c.number("count", s.count, Range::closed(0, 1e9), "messages to send, 0 for no limit");
  c.number("rate_hz", s.rate_hz, Range::above_to(0, 1e6), "messages per second");
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
  p.fill(m.centre);
  m.radius = p.real();
  m.fit_support = p.real();
  m.fit_arc = p.integer();
  m.confidence = p.real();
  m.candidates = p.below(100);
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
  m.position_sigma.resize(static_cast<size_t>(m.num_points));
  for (auto& sigma : m.position_sigma) {
    sigma.resize(3);
    for (double& v : sigma) v = p.real();
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
  m.state = p.small();
  m.state_detail = p.text();
  m.start_utime = p.integer();
  m.num_channels = p.below(5);
  for (int32_t i = 0; i < m.num_channels; ++i) {
    m.channel.push_back(p.text());
    m.messages_in.push_back(p.integer());
    m.messages_out.push_back(p.integer());
    m.rate_in_hz.push_back(p.real());
    m.rate_out_hz.push_back(p.real());
  }
  m.num_peers = p.below(5);
  for (int32_t i = 0; i < m.num_peers; ++i) {
    m.peer.push_back(p.text());
    m.peer_utime.push_back(p.integer());
    m.peer_recv_utime.push_back(p.integer());
    m.peer_offset_us.push_back(p.integer());
    m.peer_offset_error_us.push_back(p.integer());
  }
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

/// The capture time of every typical message: 2023-11-14, a plausible recent utime.
constexpr int64_t kTypicalUtime = 1700000000000000;
/// Entries of every variable array in a typical message.
constexpr int kTypicalArray = 4;

/// Fills a message with typical values, field by field (a visitor for visit_fields): strings
/// "sg-<field>", variable arrays kTypicalArray long (their length fields to match, from
/// WireLimits), numbers small and varied.
template <class M>
class TypicalFiller {
 public:
  template <class T>
  void add(const std::string& name, T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      value = "sg-" + name;
    } else if constexpr (std::is_same_v<T, bool>) {
      value = true;
    } else if constexpr (std::is_arithmetic_v<T>) {
      value = number<T>(name);
    } else if constexpr (std::is_array_v<T>) {
      for (auto& element : value) add(name, element);
    } else {
      value.resize(kTypicalArray);
      for (auto& element : value) {
        if constexpr (std::is_arithmetic_v<typename T::value_type> ||
                      std::is_same_v<typename T::value_type, std::string>) {
          add(name, element);
        } else {
          element.resize(static_cast<size_t>(inner(name)));
          for (auto& e : element) add(name, e);
        }
      }
    }
  }

 private:
  template <class T>
  T number(const std::string& name) {
    static constexpr double kReals[] = {0.45, 0.0, 0.2, 0.1, 0.5, 0.25, -0.05};
    const size_t i = counter_++;
    for (const VariableArray& a : WireLimits<M>::arrays())
      if (name == a.length_field) return static_cast<T>(kTypicalArray);
    if constexpr (std::is_floating_point_v<T>) {
      return static_cast<T>(kReals[i % std::size(kReals)]);
    } else if constexpr (sizeof(T) == 8) {
      return name == "utime" ? kTypicalUtime : kTypicalUtime + 1000;  // times, sequences
    } else if constexpr (sizeof(T) == 1 && std::is_unsigned_v<T>) {
      return static_cast<T>(i * 37 + 11);  // bytes: image pixels, MAC tags
    } else {
      return static_cast<T>(1 + i % 3);
    }
  }
  static int inner(const std::string& name) {
    for (const VariableArray& a : WireLimits<M>::arrays())
      if (name == a.name) return a.inner;
    return 1;
  }
  size_t counter_ = 0;
};

/// Where a value could move the arm or be checked for sense, a plausible one.
void make_plausible(image_t& m) {
  m.camera = image_t::LEFT;
  m.width = 2;
  m.height = 2;
  m.row_stride = 2;
  m.pixel_format = image_t::FORMAT_GRAY8;
}
void make_plausible(point3_t& m) {
  m.visible = true;
  m.position[0] = 0.45, m.position[1] = 0.0, m.position[2] = 0.10;
  for (double& s : m.position_sigma) s = 0.002;
  m.seen_by = point3_t::SEEN_LEFT | point3_t::SEEN_RIGHT;
  m.flags = 0;
}
void make_plausible(trajectory_t& m) {
  m.source_utime = m.start_utime = m.utime;
  m.period_us = 250000;
  for (int k = 0; k < m.num_points; ++k) {
    m.position[static_cast<size_t>(k)] = {0.45, 0.01 * k, 0.10};
  }
  m.status = trajectory_t::STATUS_TRACKING;
  m.model = trajectory_t::MODEL_BURG;
}
void make_plausible(arm_cmd_t& m) {
  m.source_utime = m.target_utime = m.utime;
  m.sequence = 1;
  m.mode = arm_cmd_t::MODE_CARTESIAN;
  m.position[0] = 0.45, m.position[1] = 0.0, m.position[2] = 0.20;
  for (double& v : m.orientation) v = 0.0;
  for (double& v : m.joints) v = 0.0;
  m.gripper = arm_cmd_t::GRIPPER_KEEP;
  m.speed = 0.5;
}
void make_plausible(grasp_command_t& m) {
  m.sequence = 1;
  m.command = grasp_command_t::COMMAND_TRACK;
  m.standoff = 0.10;
}
template <class T>
void make_plausible(T&) {}

template <class T>
std::vector<uint8_t> typical_as() {
  T message{};
  TypicalFiller<T> filler;
  visit_fields(message, filler);
  make_plausible(message);
  return encode_message(message);
}

struct TypeEntry {
  std::string name;
  std::string channel;
  std::function<std::vector<uint8_t>(int64_t)> encode;
  std::function<std::optional<int64_t>(const uint8_t*, int)> decode_utime;
  std::function<std::vector<uint8_t>()> typical;
};

const std::vector<TypeEntry>& types() {
  static const std::vector<TypeEntry> entries = [] {
    std::vector<TypeEntry> list;
    for_each_message_type([&]<class T>() {
      std::string upper = T::getTypeName();
      for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      list.push_back(
          {T::getTypeName(), kChannelPrefix + upper, encode_as<T>, decode_utime<T>, typical_as<T>});
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

// ---------------------------------------------------------------------------------------------
// A hostile bus

namespace {

std::string hex(uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", v);
  return text;
}

void add_windows(const std::string& name, const std::vector<uint8_t>& base,
                 std::vector<HostilePacket>& out) {
  for (size_t at = 8; at + 4 <= base.size(); ++at) {
    for (const uint32_t value : kWindowValues) {
      HostilePacket p{
          HostileKind::kWindow,
          name + " bytes " + std::to_string(at) + "-" + std::to_string(at + 3) + " = " + hex(value),
          base};
      for (int b = 0; b < 4; ++b) p.bytes[at + b] = static_cast<uint8_t>(value >> (24 - 8 * b));
      out.push_back(std::move(p));
    }
  }
}

void add_random_bodies(const std::string& name, const std::vector<uint8_t>& base, int type,
                       const HostileSettings& settings, std::vector<HostilePacket>& out) {
  Pattern random(static_cast<int64_t>(settings.seed * 0x100000001B3ULL + type + 1));
  const int32_t longest = static_cast<int32_t>(2 * base.size());
  for (int k = 0; k < settings.random_bodies; ++k) {
    const size_t length = static_cast<size_t>(random.below(longest + 1));
    HostilePacket p{
        HostileKind::kRandom,
        name + " random body " + std::to_string(k) + ": 8 + " + std::to_string(length) + " bytes",
        std::vector<uint8_t>(base.begin(), base.begin() + 8)};
    for (size_t i = 0; i < length; ++i) p.bytes.push_back(static_cast<uint8_t>(random.next()));
    out.push_back(std::move(p));
  }
}

}  // namespace

int type_index(const std::string& name) {
  for (int i = 0; i < type_count(); ++i)
    if (types()[static_cast<size_t>(i)].name == name) return i;
  return -1;
}

std::vector<uint8_t> typical(int type_index) {
  return types().at(static_cast<size_t>(type_index)).typical();
}

std::vector<HostilePacket> hostile_packets(int type, const HostileSettings& settings) {
  const std::string name = type_name(type);
  const std::vector<uint8_t> base = typical(type);
  std::vector<HostilePacket> out;
  if (settings.windows) add_windows(name, base, out);
  add_random_bodies(name, base, type, settings, out);
  if (settings.truncations) {
    for (size_t length = 0; length < base.size(); ++length) {
      out.push_back({HostileKind::kTruncated,
                     name + " truncated to " + std::to_string(length) + " bytes",
                     std::vector<uint8_t>(base.begin(), base.begin() + length)});
    }
  }
  if (settings.foreign) {
    for (int other = 0; other < type_count(); ++other) {
      if (other == type) continue;
      out.push_back({HostileKind::kForeign,
                     "a " + type_name(other) + " on the " + name + " channel", typical(other)});
    }
  }
  return out;
}

const std::vector<SystemChannel>& system_channels() {
  static const std::vector<SystemChannel> list = {{"CAMERA_LEFT", "image_t"},
                                                  {"CAMERA_RIGHT", "image_t"},
                                                  {"BLOB_LEFT", "blob_t"},
                                                  {"BLOB_RIGHT", "blob_t"},
                                                  {"OBJECT_POSITION", "point3_t"},
                                                  {"GROUND_TRUTH", "point3_t"},
                                                  {"OBJECT_TRAJECTORY", "trajectory_t"},
                                                  {"ARM_COMMAND", "arm_cmd_t"},
                                                  {"ARM_STATUS", "arm_status_t"},
                                                  {"GRASP_COMMAND", "grasp_command_t"},
                                                  {"GRASP_STATUS", "grasp_status_t"},
                                                  {"SIM_ARM_STATE", "sim_arm_state_t"}};
  return list;
}

int64_t HostilePlan::total() const {
  int64_t n = 0;
  for (const ChannelAttack& c : channels) n += static_cast<int64_t>(c.packets.size());
  return n;
}

const HostilePacket* HostilePlan::at(int64_t number, std::string* channel) const {
  // Round robin: in round r, every channel that still has an r-th packet sends it, in order.
  if (number < 0) return nullptr;
  for (size_t round = 0;; ++round) {
    bool any = false;
    for (const ChannelAttack& c : channels) {
      if (round >= c.packets.size()) continue;
      any = true;
      if (number-- == 0) {
        if (channel != nullptr) *channel = c.target.channel;
        return &c.packets[round];
      }
    }
    if (!any) return nullptr;
  }
}

HostilePlan plan_attack(const std::vector<std::string>& channels, const HostileSettings& settings) {
  HostilePlan plan;
  for (const SystemChannel& c : system_channels()) {
    if (!channels.empty() &&
        std::find(channels.begin(), channels.end(), c.channel) == channels.end())
      continue;
    plan.channels.push_back({c, hostile_packets(type_index(c.type), settings), 0});
  }
  for (const std::string& name : channels) {
    const bool known =
        std::any_of(plan.channels.begin(), plan.channels.end(),
                    [&](const ChannelAttack& c) { return c.target.channel == name; });
    if (!known) {
      std::string list;
      for (const SystemChannel& c : system_channels())
        list += (list.empty() ? "" : ", ") + c.channel;
      throw std::invalid_argument("unknown channel '" + name + "' (the system reads " + list + ")");
    }
  }
  return plan;
}

int64_t run_attack(
    HostilePlan& plan, int64_t first, int64_t last, double rate_hz,
    const std::function<bool(const std::string& channel, const HostilePacket&)>& publish,
    const std::function<void(int64_t sent, int64_t due)>& progress,
    const std::function<bool()>& stop) {
  using namespace std::chrono;
  first = std::max<int64_t>(first, 0);
  last = std::min(last, plan.total() - 1);
  const int64_t due = std::max<int64_t>(0, last - first + 1);
  const auto start = steady_clock::now();
  const auto period = duration<double>(1.0 / rate_hz);
  auto next_progress = start + seconds(1);
  int64_t sent = 0;
  // Walk the round robin once, sending the numbered range.
  int64_t number = 0;
  for (size_t round = 0; number <= last; ++round) {
    bool any = false;
    for (ChannelAttack& c : plan.channels) {
      if (round >= c.packets.size()) continue;
      any = true;
      if (number++ < first) continue;
      if (number - 1 > last || stop()) return sent;
      publish(c.target.channel, c.packets[round]);
      ++c.sent;
      ++sent;
      std::this_thread::sleep_until(start + duration_cast<steady_clock::duration>(period * sent));
      if (steady_clock::now() >= next_progress) {
        progress(sent, due);
        next_progress += seconds(1);
      }
    }
    if (!any) break;
  }
  return sent;
}

std::string attack_summary(const HostilePlan& plan) {
  std::string text;
  char line[256];
  int64_t sent = 0;
  for (const ChannelAttack& c : plan.channels) {
    int64_t kinds[4] = {0, 0, 0, 0};
    for (const HostilePacket& p : c.packets) ++kinds[static_cast<int>(p.kind)];
    std::snprintf(line, sizeof line,
                  "  %-18s %-16s %7lld of %7zu sent (%lld windows, %lld random, %lld truncated, "
                  "%lld foreign)\n",
                  c.target.channel.c_str(), c.target.type.c_str(), static_cast<long long>(c.sent),
                  c.packets.size(), static_cast<long long>(kinds[0]),
                  static_cast<long long>(kinds[1]), static_cast<long long>(kinds[2]),
                  static_cast<long long>(kinds[3]));
    text += line;
    sent += c.sent;
  }
  std::snprintf(line, sizeof line, "  %-18s %-16s %7lld of %7lld sent\n", "all", "",
                static_cast<long long>(sent), static_cast<long long>(plan.total()));
  return text + line;
}

}  // namespace sg::bus_check
