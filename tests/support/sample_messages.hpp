#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "tests/support/field_dump.hpp"

namespace sg::test {

/// Kinds of sample message for encode/decode tests.
enum class SampleKind {
  kEmpty,    ///< zeros, empty arrays and strings
  kTypical,  ///< moderate varied values, short arrays
  kExtreme,  ///< NaN, infinities, DBL_MAX, denormals, -0.0, integer limits, long arrays
};

/// Fills every field of a message according to a SampleKind (a visitor for visit_fields).
class SampleFiller {
 public:
  explicit SampleFiller(SampleKind kind) : kind_(kind) {}

  template <class T>
  void add(const std::string& name, T& value) {
    if constexpr (std::is_same_v<T, double>) {
      value = next_double();
    } else if constexpr (std::is_integral_v<T>) {
      value = next_integer<T>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      value = kind_ == SampleKind::kEmpty     ? ""
              : kind_ == SampleKind::kTypical ? "sg-" + name
                                              : std::string(4000, 'x') + " \xC2\xB5m \xC3\xA9";
    } else if constexpr (std::is_same_v<T, std::vector<uint8_t>>) {
      value.resize(kind_ == SampleKind::kEmpty ? 0 : kind_ == SampleKind::kTypical ? 64 : 921600);
      for (size_t i = 0; i < value.size(); ++i) value[i] = static_cast<uint8_t>(i * 7 + 3);
    } else if constexpr (std::is_same_v<T, std::vector<std::vector<double>>>) {
      // The only variable 2-D array is trajectory_t.position[n][3].
      value.assign(kind_ == SampleKind::kEmpty     ? 0
                   : kind_ == SampleKind::kTypical ? 16
                                                   : 10000,
                   std::vector<double>(3));
      for (auto& row : value) add(name, row);
    } else if constexpr (std::is_array_v<T>) {
      for (auto& element : value) add(name, element);
    } else {
      for (auto& element : value) add(name, element);
    }
  }

 private:
  double next_double() {
    static constexpr double kTypical[] = {0.25, -1.5, 3.0e-3, 42.0, -7.125, 0.15};
    static const double kExtreme[] = {std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::infinity(),
                                      -std::numeric_limits<double>::infinity(),
                                      std::numeric_limits<double>::max(),
                                      -std::numeric_limits<double>::max(),
                                      std::numeric_limits<double>::denorm_min(),
                                      -0.0,
                                      std::numeric_limits<double>::epsilon()};
    const size_t i = counter_++;
    if (kind_ == SampleKind::kEmpty) return 0.0;
    if (kind_ == SampleKind::kTypical) return kTypical[i % std::size(kTypical)] * (1.0 + i);
    return kExtreme[i % std::size(kExtreme)];
  }

  template <class T>
  T next_integer() {
    const size_t i = counter_++;
    if (kind_ == SampleKind::kEmpty) return 0;
    if (kind_ == SampleKind::kTypical) return static_cast<T>(i % 5);
    const T extremes[] = {std::numeric_limits<T>::max(), std::numeric_limits<T>::min(),
                          static_cast<T>(-1), static_cast<T>(1)};
    return extremes[i % 4];
  }

  SampleKind kind_;
  size_t counter_ = 0;
};

/// Makes array-length fields agree with their arrays, as any publisher must, and booleans 0 or 1
/// (lcm-gen's C++ keeps a boolean in an int8_t; Java reads any non-zero byte as true).
inline void make_consistent(stereograsp::image_t& m) {
  m.size = static_cast<int32_t>(m.data.size());
}
inline void make_consistent(stereograsp::trajectory_t& m) {
  m.num_points = static_cast<int32_t>(m.position.size());
  m.position_sigma.resize(m.position.size(), std::vector<double>(3, 0.0));
  for (auto& s : m.position_sigma) s.resize(3, 0.0);
}
/// Channels and peers as many as num_channels and num_peers say, within the bound of 64.
inline void make_consistent(stereograsp::process_status_t& m) {
  m.num_channels = std::clamp<int32_t>(m.num_channels, 0, 64);
  m.num_peers = std::clamp<int32_t>(m.num_peers, 0, 64);
  const auto channels = static_cast<size_t>(m.num_channels);
  const auto peers = static_cast<size_t>(m.num_peers);
  m.channel.resize(channels);
  for (size_t i = 0; i < channels; ++i) m.channel[i] = "SG_CHANNEL_" + std::to_string(i);
  m.messages_in.resize(channels, 7);
  m.messages_out.resize(channels, -1);
  m.rate_in_hz.resize(channels, 4.0);
  m.rate_out_hz.resize(channels, std::numeric_limits<double>::quiet_NaN());
  m.peer.resize(peers);
  for (size_t i = 0; i < peers; ++i) m.peer[i] = "sg-peer@host:" + std::to_string(i);
  m.peer_utime.resize(peers, 1700000000000000);
  m.peer_recv_utime.resize(peers, std::numeric_limits<int64_t>::min());
  m.peer_offset_us.resize(peers, 0);
  m.peer_offset_error_us.resize(peers, -1);
  m.num_unvouched = std::clamp<int32_t>(m.num_unvouched, 0, 64);
  const auto refusals = static_cast<size_t>(m.num_unvouched);
  m.unvouched_channel.resize(refusals, "OBJECT_TRAJECTORY");
  m.unvouched_sender.resize(refusals, "sg-predictor");
  m.unvouched_verdict.resize(refusals, "bad tag");
  m.unvouched_count.resize(refusals, 3);
}
inline void make_consistent(stereograsp::blob_t& m) { m.found = m.found != 0; }
inline void make_consistent(stereograsp::point3_t& m) { m.visible = m.visible != 0; }
inline void make_consistent(stereograsp::arm_cmd_t& m) { m.take_over = m.take_over != 0; }
inline void make_consistent(stereograsp::sim_arm_state_t& m) {
  m.holding_object = m.holding_object != 0;
}
template <class T>
void make_consistent(T&) {}

/// A message of type T filled according to `kind`.
template <class T>
T make_sample(SampleKind kind) {
  T message{};
  SampleFiller filler(kind);
  visit_fields(message, filler);
  make_consistent(message);
  return message;
}

}  // namespace sg::test
