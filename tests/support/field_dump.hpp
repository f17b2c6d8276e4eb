#pragma once

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "common/message_types.hpp"

namespace sg::test {

/// Every field of a message as `path=value` lines in path order, in a form that a Java program
/// produces too (tests/lcmtypes/LcmDump.java): doubles by their bits (`d:7ff8000000000000`, so NaN
/// and -0.0 compare exactly), integers and booleans in decimal (booleans 0/1), strings and byte
/// arrays as hex (`s:...`, `x:...`; over 64 bytes as length and 64-bit FNV-1a hash,
/// `x:#921600:...`), array elements as `name[i]`.
class FieldDump {
 public:
  template <class T>
  void add(const std::string& name, const T& value) {
    if constexpr (std::is_same_v<T, double>) {
      uint64_t bits = 0;
      std::memcpy(&bits, &value, sizeof bits);
      char text[24];
      std::snprintf(text, sizeof text, "d:%016" PRIx64, bits);
      fields_[name] = text;
    } else if constexpr (std::is_integral_v<T>) {
      fields_[name] = std::to_string(static_cast<long long>(value));
    } else if constexpr (std::is_same_v<T, std::string>) {
      fields_[name] = "s:" + hex(value.data(), value.size());
    } else if constexpr (std::is_same_v<T, std::vector<uint8_t>>) {
      fields_[name] = "x:" + hex(value.data(), value.size());
    } else if constexpr (std::is_array_v<T>) {
      for (size_t i = 0; i < std::extent_v<T>; ++i)
        add(name + "[" + std::to_string(i) + "]", value[i]);
    } else {  // std::vector of anything else
      for (size_t i = 0; i < value.size(); ++i) add(name + "[" + std::to_string(i) + "]", value[i]);
    }
  }

  std::string text() const {
    std::string out;
    for (const auto& [path, value] : fields_) out += path + "=" + value + "\n";
    return out;
  }

 private:
  static std::string hex(const void* data, size_t size) {
    static const char* digits = "0123456789abcdef";
    std::string out;
    const auto* bytes = static_cast<const uint8_t*>(data);
    if (size > 64) {
      uint64_t hash = 0xcbf29ce484222325ULL;
      for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
      char text[48];
      std::snprintf(text, sizeof text, "#%zu:%016" PRIx64, size, hash);
      return text;
    }
    for (size_t i = 0; i < size; ++i) {
      out += digits[bytes[i] >> 4];
      out += digits[bytes[i] & 15];
    }
    return out;
  }

  std::map<std::string, std::string> fields_;
};

// clang-format off
/// Each type's fields, in any order, for a visitor with `template <class T> add(name, T& value)`.
#define SG_FIELD(f) v.add(#f, m.f)

template <class V>
inline void visit_fields(stereograsp::image_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(camera); SG_FIELD(frame_number); SG_FIELD(width); SG_FIELD(height);
  SG_FIELD(row_stride); SG_FIELD(pixel_format); SG_FIELD(size); SG_FIELD(data);
}
template <class V>
inline void visit_fields(stereograsp::blob_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(camera); SG_FIELD(frame_number); SG_FIELD(found); SG_FIELD(mode);
  SG_FIELD(centroid); SG_FIELD(area); SG_FIELD(major_axis); SG_FIELD(minor_axis);
  SG_FIELD(orientation); SG_FIELD(major_axis_ends); SG_FIELD(minor_axis_ends);
  SG_FIELD(bounding_box); SG_FIELD(search_window); SG_FIELD(num_regions); SG_FIELD(misses);
}
template <class V>
inline void visit_fields(stereograsp::point3_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(visible); SG_FIELD(position); SG_FIELD(position_sigma);
  SG_FIELD(reprojection_error); SG_FIELD(seen_by); SG_FIELD(flags);
}
template <class V>
inline void visit_fields(stereograsp::trajectory_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(source_utime); SG_FIELD(start_utime); SG_FIELD(period_us);
  SG_FIELD(num_points); SG_FIELD(position); SG_FIELD(occluded_samples); SG_FIELD(status);
  SG_FIELD(model); SG_FIELD(model_order);
}
template <class V>
inline void visit_fields(stereograsp::arm_cmd_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(source_utime); SG_FIELD(target_utime); SG_FIELD(sequence);
  SG_FIELD(mode); SG_FIELD(position); SG_FIELD(orientation); SG_FIELD(joints); SG_FIELD(gripper);
  SG_FIELD(speed); SG_FIELD(sender);
}
template <class V>
inline void visit_fields(stereograsp::arm_status_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(state); SG_FIELD(joints); SG_FIELD(tool_position);
  SG_FIELD(tool_orientation); SG_FIELD(gripper); SG_FIELD(last_received_sequence);
  SG_FIELD(last_executed_sequence); SG_FIELD(last_rejected_sequence); SG_FIELD(rejection_reason);
  SG_FIELD(source_utime); SG_FIELD(interaction_time); SG_FIELD(speed); SG_FIELD(error);
}
template <class V>
inline void visit_fields(stereograsp::grasp_command_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(sequence); SG_FIELD(command); SG_FIELD(standoff); SG_FIELD(sender);
}
template <class V>
inline void visit_fields(stereograsp::grasp_status_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(source_utime); SG_FIELD(state); SG_FIELD(activity);
  SG_FIELD(last_action); SG_FIELD(target); SG_FIELD(target_utime); SG_FIELD(outcome);
  SG_FIELD(message);
}
template <class V>
inline void visit_fields(stereograsp::sim_arm_state_t& m, V& v) {
  SG_FIELD(utime); SG_FIELD(joints); SG_FIELD(tool_position); SG_FIELD(tool_orientation);
  SG_FIELD(gripper_opening); SG_FIELD(holding_object);
}

// clang-format on
#undef SG_FIELD

/// The dump of one message, headed by its type name and fingerprint.
template <class Message>
std::string dump(Message message) {
  FieldDump d;
  visit_fields(message, d);
  char fingerprint[40];
  std::snprintf(fingerprint, sizeof fingerprint, "fingerprint=%016" PRIx64 "\n",
                static_cast<uint64_t>(Message::getHash()));
  return std::string("type=") + Message::getTypeName() + "\n" + fingerprint + d.text();
}

}  // namespace sg::test
