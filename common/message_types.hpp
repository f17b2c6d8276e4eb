#pragma once

#include <cstdint>
#include <tuple>
#include <vector>

#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"
#include "stereograsp/blob_t.hpp"
#include "stereograsp/grasp_command_t.hpp"
#include "stereograsp/grasp_status_t.hpp"
#include "stereograsp/image_t.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/process_status_t.hpp"
#include "stereograsp/sim_arm_state_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace sg {

/// Every stereograsp message type, for code that handles all of them alike (bus checks, log
/// readers, tests). Add a type here when adding a .lcm file, and its fields to
/// common/message_fields.hpp.
using MessageTypes = std::tuple<stereograsp::image_t, stereograsp::blob_t, stereograsp::point3_t,
                                stereograsp::trajectory_t, stereograsp::arm_cmd_t,
                                stereograsp::arm_status_t, stereograsp::grasp_command_t,
                                stereograsp::grasp_status_t, stereograsp::sim_arm_state_t,
                                stereograsp::process_status_t>;

/// Calls `fn.template operator()<T>()` for each type T in MessageTypes.
template <class Fn>
void for_each_message_type(Fn&& fn) {
  [&]<class... T>(std::tuple<T...>*) {
    (fn.template operator()<T>(), ...);
  }(static_cast<MessageTypes*>(nullptr));
}

/// The encoded bytes of one message (fingerprint first), as LCM sends them.
template <class Message>
std::vector<uint8_t> encode_message(const Message& message) {
  std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
  message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

}  // namespace sg
